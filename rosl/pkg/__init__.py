"""Packages: package.xml manifests, executables, and ``pkg create`` scaffolds.

Finding package folders on the search path is ``rosl.idl.search_path``'s job (interfaces
need it too); this package adds what a package *is* to a user. Must not import node/, bus/,
graph/, launch/, sim/, bag/ or cli/.
"""
