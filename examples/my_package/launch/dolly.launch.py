"""The second tutorial's scene: Dolly in its field, driven by obstacle_avoidance.launch.py.

rosl launch my_package dolly.launch.py [real_time_factor:=1.0]

Dolly's topics live under /dolly; the included launch file remaps the node's generic
`laser_scan` and `cmd_vel` to them, exactly as in the tutorial.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration, PathJoinSubstitution
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "real_time_factor", default_value="1.0", description="Sim time per wall time"
            ),
            Node(
                package="rosl_sim",
                executable="sim",
                output="screen",
                arguments=[
                    "dolly_field",
                    "--headless",
                    "--real-time-factor",
                    LaunchConfiguration("real_time_factor"),
                ],
            ),
            IncludeLaunchDescription(
                PythonLaunchDescriptionSource(
                    PathJoinSubstitution(
                        [FindPackageShare("my_package"), "launch", "obstacle_avoidance.launch.py"]
                    )
                )
            ),
        ]
    )
