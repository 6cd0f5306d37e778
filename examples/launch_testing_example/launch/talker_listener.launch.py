from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(package="launch_testing_example", executable="talker", output="screen"),
            Node(package="launch_testing_example", executable="listener", output="screen"),
        ]
    )
