"""The robot description read from the package's share folder and handed to a node, beside a
publisher of the robot's sensors (after ros2/demos' dummy_robot_bringup.launch.py)."""

import os

from launch import LaunchDescription
from launch_ros.actions import Node
from launch_ros.substitutions import FindPackageShare


def generate_launch_description():
    pkg_share = FindPackageShare("dummy_robot_check").find("dummy_robot_check")
    urdf_file = os.path.join(pkg_share, "launch", "single_rrbot.urdf")
    with open(urdf_file) as infp:
        robot_desc = infp.read()
    rsp_params = {"robot_description": robot_desc}
    return LaunchDescription(
        [
            Node(
                package="dummy_robot_check",
                executable="description_echo",
                output="screen",
                parameters=[rsp_params],
            ),
            Node(
                package="demo_nodes_py",
                executable="talker",
                name="dummy_joint_states",
                output="screen",
                remappings=[("chatter", "joint_states_text")],
            ),
        ]
    )
