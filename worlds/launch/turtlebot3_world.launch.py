"""The TurtleBot3 arena, paced at real time (turtlebot3_gazebo's turtlebot3_world.launch.py).

rosl launch rosl_sim turtlebot3_world.launch.py [world:=empty] [real_time_factor:=1.0]
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "world",
                default_value="turtlebot3_world",
                description="A shipped world's name or a world file",
            ),
            DeclareLaunchArgument(
                "real_time_factor", default_value="1.0", description="Sim time per wall time"
            ),
            Node(
                package="rosl_sim",
                executable="sim",
                output="screen",
                arguments=[
                    LaunchConfiguration("world"),
                    "--headless",
                    "--real-time-factor",
                    LaunchConfiguration("real_time_factor"),
                ],
            ),
        ]
    )
