"""Launch a talker and a listener."""

import launch_ros.actions
from launch import LaunchDescription


def generate_launch_description():
    return LaunchDescription(
        [
            launch_ros.actions.Node(package="demo_nodes_py", executable="talker", output="screen"),
            launch_ros.actions.Node(
                package="demo_nodes_py", executable="listener", output="screen"
            ),
        ]
    )
