"""Environment, event handlers, OpaqueFunction and a Shutdown event, in one launch that ends."""

import launch
import launch_ros.actions
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
from launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart
from launch.substitutions import FindExecutable, LaunchConfiguration, ThisLaunchFileDir


def missing_package():
    try:
        get_package_share_directory("no_such_package")
    except KeyError:  # ament's PackageNotFoundError is a KeyError
        return "no_such_package is not installed"
    return "no_such_package was found"


def after_shell(context):
    word = LaunchConfiguration("word").perform(context)
    return [LogInfo(msg=f"opaque saw word={word} and {context.launch_configurations['word']}")]


def generate_launch_description():
    sleeper = ExecuteProcess(cmd=[FindExecutable(name="sleep"), "60"], name="sleeper")
    show = ExecuteProcess(
        cmd=[
            FindExecutable(name="sh"),
            "-c",
            'echo "cwd=$(pwd) API_PATH=$API_PATH API_SET=$API_SET EXTRA=$EXTRA"',
        ],
        name="show_env",
        output="screen",
        cwd=ThisLaunchFileDir(),
        additional_env={"EXTRA": "more"},
    )
    shell = ExecuteProcess(
        cmd=["echo", LaunchConfiguration("word"), "|", "tr", "a-z", "A-Z"],
        shell=True,
        name="shell",
        output="screen",
    )
    clean = ExecuteProcess(
        cmd=["/bin/sh", "-c", 'echo "clean API_SET=${API_SET:-unset} ONLY=$ONLY"'],
        env={"ONLY": "this"},
        name="clean_env",
        output="screen",
    )
    reader = launch_ros.actions.Node(
        package="python_api_check", executable="share_reader", output="screen"
    )
    return LaunchDescription(
        [
            launch.actions.DeclareLaunchArgument("word", default_value="quiet"),
            launch.actions.SetEnvironmentVariable("API_SET", "set"),
            launch.actions.AppendEnvironmentVariable("API_PATH", "middle"),
            launch.actions.AppendEnvironmentVariable("API_PATH", "last", separator=";"),
            launch.actions.AppendEnvironmentVariable("API_PATH", "first", prepend=True),
            LogInfo(msg=["share ", get_package_share_directory("python_api_check")]),
            LogInfo(msg=missing_package()),
            RegisterEventHandler(
                OnProcessStart(target_action=show, on_start=[LogInfo(msg="show_env started")])
            ),
            RegisterEventHandler(
                OnProcessIO(
                    target_action=shell,
                    on_stdout=lambda event: LogInfo(
                        msg=f"shell said {event.text.decode().strip()}"
                    ),
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=show,
                    on_exit=lambda event, context: [
                        LogInfo(msg=f"show_env exited with {event.returncode}"),
                        shell,
                    ],
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=shell,
                    on_exit=[clean, reader, launch.actions.OpaqueFunction(function=after_shell)],
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=lambda action: action is clean or action is reader,
                    on_exit=[LogInfo(msg="one of clean_env and share_reader exited")],
                )
            ),
            RegisterEventHandler(
                OnProcessExit(
                    target_action=lambda action: action in (clean, reader),
                    handle_once=True,
                    on_exit=[LogInfo(msg="the first of clean_env and share_reader exited")],
                )
            ),
            RegisterEventHandler(
                launch.event_handlers.OnProcessExit(
                    target_action=reader,
                    on_exit=[
                        launch.actions.EmitEvent(event=launch.events.Shutdown(reason="all checked"))
                    ],
                )
            ),
            sleeper,
            show,
        ]
    )
