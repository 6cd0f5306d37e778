"""The root of every error rosl reports to a user.

Only ``rosl.cli.main`` prints errors and picks exit codes: a ``RoslError`` becomes one stderr
line and exit 1. Each subpackage defines its own subclasses in its ``errors.py``::

    RoslError
    ├── InterfaceError      idl/      a .msg/.srv file, a type name, a message value
    │   └── FieldError                a message field that does not exist or has a wrong value
    ├── PackageError        pkg/      package.xml, package lookup, executables
    ├── BusError            bus/      sockets, multicast setup, datagrams
    ├── GraphError          graph/    unknown node/topic/service, discovery timeouts
    ├── NodeError           node/     names, parameters, QoS, services, --ros-args
    ├── LaunchError         launch/   launch files, arguments, processes
    ├── BagError            bag/      recordings: metadata, MCAP files, diffs
    └── WorldFileError      sim/      world and robot files
"""

from __future__ import annotations


class RoslError(Exception):
    """An error caused by the user's input or environment, reported as one line."""

    exit_code: int = 1
