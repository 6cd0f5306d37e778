"""Launching: the launch API, loading launch files, and supervising the processes they start.

The API mirrors ROS 2's ``launch`` and ``launch_ros`` (``LaunchDescription``, ``Node``,
``DeclareLaunchArgument``, substitutions, conditions, event handlers); launch files import it
through the ``launch``/``launch_ros`` aliases and run unchanged. The supervisor starts every
process in its own process group with a parent-death signal, prefixes output ``[name-N]``,
escalates SIGINT → SIGTERM → SIGKILL on shutdown, and leaves no process behind. Imports
``rosl.pkg`` (packages, executables), ``rosl.node.ros_args`` and, for lifecycle nodes, a node
of the launcher's own (``lifecycle.py``); never the CLI.
"""
