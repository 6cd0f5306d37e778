"""Nodes of a dummy robot, for launch files written after ros2/demos dummy_robot_bringup."""
