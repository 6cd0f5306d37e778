"""A launch test of the managed talker, driven by launch events (after ros2/demos' lifecycle_py).

The talker is configured as it starts, activated once inactive, deactivated a moment after it
is active, then cleaned up and shut down; the listener must hear it while it is active.
"""

import re
import unittest

import launch
import launch.actions
import launch.event_handlers
import launch.events
import launch_ros.actions
import launch_ros.event_handlers
import launch_ros.events.lifecycle
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import lifecycle_msgs.msg
import pytest


def request(node, transition_id):
    return launch.actions.EmitEvent(
        event=launch_ros.events.lifecycle.ChangeState(
            lifecycle_node_matcher=launch.events.matches_action(node),
            transition_id=transition_id,
        )
    )


def when(node, start_state, goal_state, *entities):
    return launch.actions.RegisterEventHandler(
        launch_ros.event_handlers.OnStateTransition(
            target_lifecycle_node=node,
            start_state=start_state,
            goal_state=goal_state,
            entities=list(entities),
        )
    )


@pytest.mark.launch_test
def generate_test_description():
    transition = lifecycle_msgs.msg.Transition
    talker_node = launch_ros.actions.LifecycleNode(
        package="lifecycle",
        executable="lifecycle_talker",
        name="lc_talker",
        namespace="",
        output="screen",
    )
    listener_node = launch_ros.actions.Node(
        package="lifecycle", executable="lifecycle_listener", name="listener", output="screen"
    )
    return launch.LaunchDescription(
        [
            talker_node,
            listener_node,
            launch.actions.RegisterEventHandler(
                launch.event_handlers.OnProcessStart(
                    target_action=talker_node,
                    on_start=[request(talker_node, transition.TRANSITION_CONFIGURE)],
                )
            ),
            when(
                talker_node,
                "configuring",
                "inactive",
                request(talker_node, transition.TRANSITION_ACTIVATE),
            ),
            when(
                talker_node,
                "activating",
                "active",
                launch.actions.TimerAction(
                    period=3.0, actions=[request(talker_node, transition.TRANSITION_DEACTIVATE)]
                ),
            ),
            when(
                talker_node,
                "deactivating",
                "inactive",
                request(talker_node, transition.TRANSITION_CLEANUP),
            ),
            when(
                talker_node,
                "cleaningup",
                "unconfigured",
                request(talker_node, transition.TRANSITION_UNCONFIGURED_SHUTDOWN),
            ),
            launch_testing.actions.ReadyToTest(),
        ]
    ), {"talker_node": talker_node, "listener_node": listener_node}


class TestManagedTalker(unittest.TestCase):
    def test_talker_goes_through_its_states(self, proc_output, talker_node, listener_node):
        proc_output.assertWaitFor("on_configure() is called", process=talker_node, timeout=30)
        proc_output.assertWaitFor("on_activate() is called", process=talker_node, timeout=30)
        heard = re.compile(r"data_callback: Lifecycle HelloWorld #\d+")
        proc_output.assertWaitFor(expected_output=heard, process=listener_node, timeout=30)
        proc_output.assertWaitFor("on_deactivate() is called", process=talker_node, timeout=30)
        proc_output.assertWaitFor("on_cleanup() is called", process=talker_node, timeout=30)
        proc_output.assertWaitFor("on_shutdown() is called", process=talker_node, timeout=30)


@launch_testing.post_shutdown_test()
class TestManagedTalkerAfterShutdown(unittest.TestCase):
    def test_talker_exits_cleanly(self, proc_info, talker_node):
        launch_testing.asserts.assertExitCodes(proc_info, process=talker_node)
