"""Launch an add_two_ints server and a client; the launch ends with the client."""

import launch
import launch_ros.actions


def generate_launch_description():
    server = launch_ros.actions.Node(
        package="demo_nodes_py", executable="add_two_ints_server", output="screen"
    )
    client = launch_ros.actions.Node(
        package="demo_nodes_py", executable="add_two_ints_client", output="screen"
    )
    return launch.LaunchDescription(
        [
            server,
            client,
            # once the client has its answer, nothing is left to do: shut the launch down
            launch.actions.RegisterEventHandler(
                event_handler=launch.event_handlers.OnProcessExit(
                    target_action=client,
                    on_exit=[launch.actions.EmitEvent(event=launch.events.Shutdown())],
                )
            ),
        ]
    )
