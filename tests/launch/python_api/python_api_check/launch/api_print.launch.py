"""What `rosl launch --print` must show: every substitution resolved, conditions applied."""

import os

import launch
import launch_ros
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.substitutions import LaunchConfiguration


def say_mode(context):
    mode = LaunchConfiguration("mode").perform(context)
    return [launch.actions.ExecuteProcess(cmd=["echo", f"opaque saw {mode}"], name="opaque")]


def generate_launch_description():
    mode = LaunchConfiguration("mode")
    timer_file = os.path.join(
        get_package_share_directory("python_api_check"), "config", "timer.yaml"
    )
    share = launch_ros.substitutions.FindPackageShare("python_api_check")
    return LaunchDescription(
        [
            launch.actions.DeclareLaunchArgument(
                "mode", default_value="fast", choices=["fast", "slow"]
            ),
            launch.actions.DeclareLaunchArgument("period", default_value="0.25"),
            launch_ros.actions.Node(
                package="tutorial_pkg",
                executable="timer_node",
                name="fast_timer",
                parameters=[{"timer_period_s": LaunchConfiguration("period")}],
                condition=launch.conditions.LaunchConfigurationEquals("mode", "fast"),
            ),
            launch_ros.actions.Node(
                package="tutorial_pkg",
                executable="timer_node",
                name="slow_timer",
                parameters=[launch_ros.parameter_descriptions.ParameterFile(timer_file)],
                condition=launch.conditions.IfCondition(
                    launch.substitutions.PythonExpression(["'", mode, "' == 'slow'"])
                ),
            ),
            launch.actions.ExecuteProcess(
                cmd=[launch.substitutions.FindExecutable(name="sh"), "-c", "exit 0"], name="finder"
            ),
            launch.actions.ExecuteProcess(
                cmd=[
                    launch_ros.substitutions.ExecutableInPackage(
                        executable="timer_node", package="tutorial_pkg"
                    )
                ]
            ),
            launch.actions.ExecuteProcess(
                cmd=[
                    "cat",
                    launch.substitutions.PathJoinSubstitution([share, "config", "timer.yaml"]),
                ],
                name="paths",
            ),
            launch.actions.ExecuteProcess(
                cmd=[
                    "echo",
                    launch_ros.substitutions.FindPackagePrefix("python_api_check"),
                    launch_ros.substitutions.FindPackage("python_api_check"),
                    share.find("python_api_check"),
                ],
                name="prefixes",
            ),
            launch.actions.ExecuteProcess(
                cmd=[
                    "echo",
                    [
                        launch.substitutions.EnvironmentVariable(
                            "API_CHECK_UNSET", default_value="fallback"
                        ),
                        launch.substitutions.TextSubstitution(text="+text"),
                    ],
                    launch.substitutions.ThisLaunchFileDir(),
                ],
                name="texts",
            ),
            launch.actions.ExecuteProcess(
                cmd=["echo", mode, "|", "tr", "a-z", "A-Z"], shell=True, name="piped"
            ),
            launch.actions.OpaqueFunction(function=say_mode),
        ]
    )
