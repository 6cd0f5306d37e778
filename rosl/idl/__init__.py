"""Interfaces: .msg/.srv parsing, the search path, message classes and CDR.

Owns the own parser (``file:line:col`` errors, defaults, constants, bounds), where packages
and their interface files are found, the generated message classes, YAML/dict conversion,
and CDR through rosbags' typestore (``store.py`` is the only module that imports rosbags'
type system). The helpers ROS 2 code imports are built here too, on those: field setting
and lookups by name as rosidl_runtime_py has them (``assign.py``, ``lookup.py``),
rclpy.serialization's two functions (``cdr.py``), and PointCloud2 as numpy
(``point_cloud.py``). Must not import anything else from rosl but ``rosl.errors`` and
``rosl.resources``.
"""
