"""Launch data publishers with different depth configurations."""

import launch.actions
from launch import LaunchDescription
from launch_ros.substitutions import ExecutableInPackage


def create_data_publisher_action(size, depth):
    name = f"{size}_depth_{depth}"
    payload = 0 if size == "small" else 100000
    executable = ExecutableInPackage(package="topic_monitor", executable="data_publisher")
    return launch.actions.ExecuteProcess(
        cmd=[executable, name, "--depth", str(depth), "--payload-size", str(payload)],
        output="screen",
    )


def generate_launch_description():
    return LaunchDescription(
        [
            create_data_publisher_action("small", 1),
            create_data_publisher_action("small", 50),
            create_data_publisher_action("large", 1),
            create_data_publisher_action("large", 50),
        ]
    )
