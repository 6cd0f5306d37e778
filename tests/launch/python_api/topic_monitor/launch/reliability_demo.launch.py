"""Launch data publishers with different reliability configurations."""

import launch_ros.actions
from launch import LaunchDescription


def generate_launch_description():
    return LaunchDescription(
        [
            launch_ros.actions.Node(
                package="topic_monitor",
                executable="data_publisher",
                output="screen",
                arguments=["sensor", "--best-effort"],
            ),
            launch_ros.actions.Node(
                package="topic_monitor",
                executable="data_publisher",
                output="screen",
                arguments=["critical"],
            ),
        ]
    )
