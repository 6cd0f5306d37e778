"""The velocity controller driving its square in an empty world, on sim time, drawn at the end.

rosl launch tutorial_pkg square.launch.py [duration:=15]
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("duration", default_value="15", description="Sim seconds to run"),
            DeclareLaunchArgument(
                "picture", default_value="square.png", description="Where to draw the path"
            ),
            Node(
                package="tutorial_pkg",
                executable="velocity_controller",
                parameters=[{"use_sim_time": True}],
            ),
            Node(
                package="rosl_sim",
                executable="sim",
                output="screen",
                arguments=[
                    "empty",
                    "--fast",
                    "--headless",
                    "--wait-for",
                    "velocity_controller",
                    "--duration",
                    LaunchConfiguration("duration"),
                    "--render",
                    LaunchConfiguration("picture"),
                ],
                on_exit=Shutdown(reason="the simulation ended"),
            ),
        ]
    )
