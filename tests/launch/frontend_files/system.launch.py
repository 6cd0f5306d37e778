"""One small system, written three times: system.launch.py, .xml and .yaml must agree."""

from launch import LaunchDescription
from launch.actions import (
    AppendEnvironmentVariable,
    DeclareLaunchArgument,
    ExecuteProcess,
    GroupAction,
    IncludeLaunchDescription,
    LogInfo,
    SetEnvironmentVariable,
    SetLaunchConfiguration,
    TimerAction,
)
from launch.conditions import IfCondition
from launch.launch_description_sources import AnyLaunchDescriptionSource
from launch.substitutions import (
    FindExecutable,
    LaunchConfiguration,
    PathJoinSubstitution,
    PythonExpression,
    ThisLaunchFileDir,
)
from launch_ros.actions import Node, PushRosNamespace, SetParameter, SetRemap


def generate_launch_description():
    label = LaunchConfiguration("label")
    here = ThisLaunchFileDir()
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "label",
                default_value="plain",
                description="Passed to the helper and the included file",
            ),
            DeclareLaunchArgument("use_timer", default_value="true"),
            SetLaunchConfiguration("period", PythonExpression(["0.2 * 2"])),
            SetEnvironmentVariable("SYSTEM_GREETING", ["hello ", label]),
            AppendEnvironmentVariable("SYSTEM_GREETING", "again", separator=" "),
            GroupAction(
                [
                    PushRosNamespace("demo"),
                    SetParameter(name="shared", value=7),
                    SetRemap(src="my_data", dst="system_data"),
                    Node(
                        package="tutorial_pkg",
                        executable="timer_node",
                        name="system_timer",
                        output="screen",
                        parameters=[
                            {"timer_period_s": LaunchConfiguration("period")},
                            PathJoinSubstitution([here, "params.yaml"]),
                        ],
                        condition=IfCondition(LaunchConfiguration("use_timer")),
                    ),
                    Node(
                        package="tutorial_pkg",
                        executable="my_publisher",
                        name="system_talker",
                        output="screen",
                    ),
                ]
            ),
            Node(
                package="tutorial_pkg",
                executable="my_subscriber",
                name="system_listener",
                output="screen",
                remappings=[("my_data", "/demo/system_data")],
            ),
            ExecuteProcess(
                cmd=[
                    FindExecutable(name="python3"),
                    PathJoinSubstitution([here, "echo_env.py"]),
                    label,
                ],
                name="env_echo",
                output="screen",
                additional_env={"EXTRA": ["extra ", label]},
            ),
            TimerAction(period=0.5, actions=[LogInfo(msg=["timer fired for ", label])]),
            IncludeLaunchDescription(
                AnyLaunchDescriptionSource(PathJoinSubstitution([here, "child.launch.xml"])),
                launch_arguments=[("who", label)],
            ),
        ]
    )
