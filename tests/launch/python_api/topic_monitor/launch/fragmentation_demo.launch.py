"""Launch data publishers with different payload sizes."""

import launch.actions
from launch import LaunchDescription
from launch_ros.substitutions import ExecutableInPackage


def generate_launch_description():
    executable = ExecutableInPackage(package="topic_monitor", executable="data_publisher")
    sizes = [("small", 1), ("medium", 50000), ("large", 100000), ("xlarge", 150000)]
    return LaunchDescription(
        [
            launch.actions.ExecuteProcess(
                cmd=[executable, name, "--payload-size", str(size), "--period", "4"],
                output="screen",
            )
            for name, size in sizes
        ]
    )
