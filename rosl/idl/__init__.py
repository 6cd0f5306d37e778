"""Interfaces: .msg/.srv parsing, the search path, message classes and CDR.

Owns the own parser (``file:line:col`` errors, defaults, constants, bounds), where packages
and their interface files are found, the generated message classes, YAML/dict conversion,
and CDR through rosbags' typestore (``store.py`` is the only module that imports rosbags'
type system). Must not import anything else from rosl but ``rosl.errors`` and
``rosl.resources``.
"""
