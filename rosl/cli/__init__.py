"""The ``rosl`` command line: a thin click layer over the library.

Each command parses arguments, makes one call into the subpackage that owns the concept and
renders the result. Only ``main.py`` prints errors and chooses exit codes.
"""
