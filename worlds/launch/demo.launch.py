"""The README's demo: a TurtleBot3 avoiding obstacles in its arena, recorded and drawn.

rosl launch rosl_sim demo.launch.py [duration:=60] [bag:=DIR]

The simulator runs in lock-step (--fast): as fast as the obstacle-avoidance node can answer,
with the same result on any machine. At the end it prints what happened, and leaves the bag
(read it with `rosl bag info DIR`, rosbags or any MCAP viewer) and a picture of the path.
"""

import time

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, Shutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description():
    default_bag = time.strftime("demo_%Y_%m_%d-%H_%M_%S")
    bag = LaunchConfiguration("bag")
    return LaunchDescription(
        [
            DeclareLaunchArgument("duration", default_value="60", description="Sim seconds to run"),
            DeclareLaunchArgument(
                "bag", default_value=default_bag, description="Folder of the bag"
            ),
            Node(
                package="my_package",
                executable="obstacle_avoidance",
                name="obstacle_avoidance",
                remappings=[("laser_scan", "/scan"), ("cmd_vel", "/cmd_vel")],
                ros_arguments=["--log-level", "warn"],  # its "Distance is" line at 5 Hz: not here
                parameters=[
                    {
                        "use_sim_time": True,
                        "distance_threshold": 0.5,  # the Burger is 0.2 m wide; its arena is small
                        "field_of_view": 1.2,  # look +-34 degrees ahead, not all around
                        "linear_speed": 0.22,  # the Burger's top speed (the tutorial's 0.3 is not)
                    }
                ],
            ),
            Node(
                package="rosl_sim",
                executable="sim",
                output="screen",
                arguments=[
                    "turtlebot3_world",
                    "--fast",
                    "--headless",
                    "--duration",
                    LaunchConfiguration("duration"),
                    "--wait-for",
                    "obstacle_avoidance",
                    "--record",
                    bag,
                    "--render",
                    [bag, ".png"],
                ],
                on_exit=Shutdown(reason="the simulation ended"),
            ),
        ]
    )
