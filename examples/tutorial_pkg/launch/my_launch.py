# launch/my_launch.py
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="tutorial_pkg",
                executable="my_publisher",
                name="publisher_node",
                output="screen",
            ),
            Node(
                package="tutorial_pkg",
                executable="my_subscriber",
                name="subscriber_node",
                output="screen",
            ),
            Node(
                package="tutorial_pkg",
                executable="timer_node",
                name="timer_node",
                output="screen",
                parameters=[{"timer_period_s": 1.5}],
            ),
        ]
    )
