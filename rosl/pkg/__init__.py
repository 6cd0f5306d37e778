"""Packages: package.xml manifests, executables, and ``pkg create`` scaffolds.

Starting an executable is part of what a package offers, so ``entry.py`` (the start-up of a
node process) and ``interrupts.py`` (how Ctrl-C reaches a program rosl starts) live here,
shared by ``rosl run`` and ``rosl launch``.

Finding package folders on the search path is ``rosl.idl.search_path``'s job (interfaces
need it too); this package adds what a package *is* to a user. Must not import node/, bus/,
graph/, launch/, sim/, bag/ or cli/.
"""
