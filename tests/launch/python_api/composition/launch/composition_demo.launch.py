"""Launch a talker and a listener in a component container."""

import launch
from launch_ros.actions import ComposableNodeContainer
from launch_ros.descriptions import ComposableNode


def generate_launch_description():
    """Generate a launch description with two components in one container."""
    container = ComposableNodeContainer(
        name="my_container",
        namespace="",
        package="rclcpp_components",
        executable="component_container",
        composable_node_descriptions=[
            ComposableNode(package="composition", plugin="composition::Talker", name="talker"),
            ComposableNode(package="composition", plugin="composition::Listener", name="listener"),
        ],
        output="screen",
    )

    return launch.LaunchDescription([container])
