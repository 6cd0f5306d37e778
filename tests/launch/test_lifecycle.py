"""Managed nodes in launch files: launch_ros' LifecycleNode, ChangeState and OnStateTransition.

ros2/demos' lifecycle launch file (its C++ nodes written in Python, tests/launch/python_api/
lifecycle), a launch file driving the talker the way ros2/demos' lifecycle_py launch test does
(ChangeState on start, then one ChangeState per OnStateTransition), XML's ``<lifecycle_node
autostart>``, and the one-line errors of bad lifecycle actions.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.conftest import REPO
from tests.launch.support import assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Output, Rosl

PACKAGES = REPO / "tests" / "launch" / "python_api"
TALKER = "[lifecycle_talker-1] "
LISTENER = "[lifecycle_listener-2] "

DRIVEN = """
import launch
import launch.actions
import launch.events
import launch_ros.actions
import launch_ros.event_handlers
import launch_ros.events.lifecycle
import lifecycle_msgs.msg


def change(node, transition):
    return launch.actions.EmitEvent(event=launch_ros.events.lifecycle.ChangeState(
        lifecycle_node_matcher=launch.events.matches_action(node),
        transition_id=transition,
    ))


def on(node, start, goal, *entities):
    return launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition(
        target_lifecycle_node=node, start_state=start, goal_state=goal, entities=list(entities),
    ))


def generate_launch_description():
    Transition = lifecycle_msgs.msg.Transition
    talker = launch_ros.actions.LifecycleNode(
        package="lifecycle", executable="lifecycle_talker", name="lc_talker", namespace="",
        output="screen",
    )
    listener = launch_ros.actions.Node(
        package="lifecycle", executable="lifecycle_listener", output="screen",
    )
    return launch.LaunchDescription([
        talker,
        listener,
        launch.actions.RegisterEventHandler(launch.event_handlers.OnProcessStart(
            target_action=talker, on_start=[change(talker, Transition.TRANSITION_CONFIGURE)],
        )),
        on(talker, "configuring", "inactive",
           launch.actions.LogInfo(msg="talker is inactive, activating"),
           change(talker, Transition.TRANSITION_ACTIVATE)),
        on(talker, "activating", "active",
           launch.actions.LogInfo(msg="talker is active"),
           launch.actions.TimerAction(period=2.0, actions=[
               change(talker, Transition.TRANSITION_DEACTIVATE)])),
        on(talker, "deactivating", "inactive", change(talker, Transition.TRANSITION_CLEANUP)),
        on(talker, "cleaningup", "unconfigured",
           change(talker, Transition.TRANSITION_UNCONFIGURED_SHUTDOWN)),
        on(talker, None, "finalized",
           launch.actions.LogInfo(msg="talker is finalized"),
           launch.actions.EmitEvent(event=launch.events.Shutdown(reason="talker finalized"))),
    ])
"""


@pytest.fixture(autouse=True)
def packages(log_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The lifecycle demo package on the package path."""
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(PACKAGES))


def talker_said(launch: Output) -> list[str]:
    """What the talker's callbacks logged, in order."""
    return [
        line.split("]: ", 1)[1]
        for line in launch.lines()
        if line.startswith(TALKER) and "() is called" in line
    ]


def refused_then_interrupted(launch: Output, transition: str, node: str) -> list[int]:
    """Wait for launch_ros' line about a refused transition, then Ctrl-C; the launched pids."""
    assert launch.wait_for(
        r"^\[ERROR\] \[launch_ros.actions.lifecycle_node\]: Failed to make transition "
        rf"'{transition}' for LifecycleNode '{node}'$",
        timeout=60.0,
    ), launch.both()
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    return pids


def test_the_real_lifecycle_demo_launch_file_runs_to_its_end(rosl: Rosl) -> None:
    launch = rosl.start("launch", "lifecycle", "lifecycle_demo.launch.py")

    # the service client drives the talker to finalized and exits: on_exit=Shutdown()
    assert launch.finish(timeout=90.0) == 0, launch.both()
    assert talker_said(launch) == [
        "on_configure() is called (from unconfigured).", "on_activate() is called.",
        "on_deactivate() is called.", "on_activate() is called.", "on_deactivate() is called.",
        "on_cleanup() is called.", "on_shutdown() is called (from unconfigured).",
    ], launch.both()  # fmt: skip
    assert launch.matching(r"\[listener\]: data_callback: Lifecycle HelloWorld #\d+$")
    assert launch.matching(
        r"\[listener\]: notify_callback: Transition from state shuttingdown to finalized$"
    ), launch.both()
    client = [line.split("]: ", 1)[1] for line in launch.lines() if "[lc_client]" in line]
    assert client[-2:] == ["Transition 5 successfully triggered.",
                           "Node lc_talker has current state finalized."]  # fmt: skip
    assert_all_gone(launch.pids())


def test_change_state_and_on_state_transition_drive_a_node_to_active_and_back(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "driven.launch.py", DRIVEN)
    launch = rosl.start("launch", str(path))

    assert launch.finish(timeout=90.0) == 0, launch.both()
    assert talker_said(launch) == [
        "on_configure() is called (from unconfigured).", "on_activate() is called.",
        "on_deactivate() is called.", "on_cleanup() is called.",
        "on_shutdown() is called (from unconfigured).",
    ], launch.both()  # fmt: skip
    said = [line for line in launch.lines() if line.startswith("[INFO] [launch.user]: ")]
    assert [line.removeprefix("[INFO] [launch.user]: ") for line in said] == [
        "talker is inactive, activating", "talker is active", "talker is finalized",
    ], launch.both()  # fmt: skip
    # the listener heard the talker while it was active (two seconds, every 0.2 s)
    assert launch.matching(r"\[listener\]: data_callback: Lifecycle HelloWorld #\d+$"), (
        launch.both()
    )
    assert_all_gone(launch.pids())


def test_a_transition_the_node_refuses_is_logged_as_launch_ros_does(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "refused.launch.py",
        """
        import launch, launch_ros, lifecycle_msgs.msg
        from launch_ros.events.lifecycle import ChangeState, matches_node_name
        def generate_launch_description():
            talker = launch_ros.actions.LifecycleNode(
                package="lifecycle", executable="lifecycle_talker", name="lc_talker",
                namespace="", output="screen")
            activate = launch.actions.EmitEvent(event=ChangeState(
                lifecycle_node_matcher=matches_node_name("/lc_talker"),
                transition_id=lifecycle_msgs.msg.Transition.TRANSITION_ACTIVATE))
            return launch.LaunchDescription([talker, launch.actions.RegisterEventHandler(
                launch.event_handlers.OnProcessStart(target_action=talker, on_start=[activate]))])
        """,
    )
    launch = rosl.start("launch", str(path))

    pids = refused_then_interrupted(launch, "TRANSITION_ACTIVATE", "/lc_talker")
    assert talker_said(launch) == []  # activate is not a transition from unconfigured
    assert_all_gone(pids)


def test_xml_lifecycle_node_with_autostart_is_configured_and_activated(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "autostart.launch.xml",
        """
        <launch>
          <lifecycle_node pkg="lifecycle" exec="lifecycle_talker" name="lc_talker"
                          namespace="" autostart="true" output="screen"/>
        </launch>
        """,
    )
    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"Lifecycle publisher is active\. Publishing", timeout=60.0), (
        launch.both()
    )
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert talker_said(launch)[:2] == [
        "on_configure() is called (from unconfigured).", "on_activate() is called.",
    ]  # fmt: skip
    assert_all_gone(pids)


@pytest.mark.parametrize(
    ("source", "message"),
    [
        (
            "launch_ros.actions.LifecycleNode(package='lifecycle', executable='lifecycle_talker')",
            "LifecycleNode(executable='lifecycle_talker') needs name=",
        ),
        (
            "launch.actions.EmitEvent(event=launch_ros.events.lifecycle.ChangeState("
            "lifecycle_node_matcher=lambda node: True, transition_id=42))",
            "ChangeState: given transition_id of '42', expected one of {TRANSITION_CREATE: 0, "
            "TRANSITION_CONFIGURE: 1,",
        ),
        (
            "launch.actions.RegisterEventHandler(launch_ros.event_handlers.OnStateTransition("
            "target_lifecycle_node=launch_ros.actions.Node(package='lifecycle', "
            "executable='lifecycle_listener'), goal_state='active', entities=[]))",
            'OnStateTransition requires a "LifecycleNode" action as the target, '
            "target_lifecycle_node is a Node",
        ),
    ],
    ids=["no-name", "bad-transition", "not-lifecycle"],
)
def test_bad_lifecycle_actions_are_one_line_naming_the_file_and_line(
    rosl: Rosl, launch_dir: Path, source: str, message: str
) -> None:
    path = write_launch(
        launch_dir,
        "bad.launch.py",
        f"""
        import launch
        import launch_ros
        def generate_launch_description():
            return launch.LaunchDescription([
                {source},
            ])
        """,
    )

    code, out, err = rosl.run("launch", "--print", str(path))

    assert code == 1, f"{out}\n{err}"
    line = one_error_line(err)
    assert line.startswith(f"{path}:"), line
    assert message in line, line


def test_xml_lifecycle_node_needs_a_name(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "noname.launch.xml",
        '<launch>\n  <lifecycle_node pkg="lifecycle" exec="lifecycle_talker"/>\n</launch>\n',
    )

    code, out, err = rosl.run("launch", "--print", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err).startswith(f"{path}:2: <lifecycle_node> needs the attribute 'name'")


def test_print_shows_a_lifecycle_node_as_the_node_it_starts(rosl: Rosl) -> None:
    code, out, err = rosl.run("launch", "--print", "lifecycle", "lifecycle_demo.launch.py")

    assert code == 0, f"{out}\n{err}"
    lines = out.splitlines()
    assert lines[0].startswith("[lifecycle_talker-1] "), out
    assert lines[0].endswith(" lifecycle_talker --ros-args -r __node:=lc_talker"), out
    assert lines[1] == "    node: lc_talker (package lifecycle, namespace /)", out


def test_lifecycle_transition_takes_each_nodes_list_and_stops_at_a_refusal(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "transitions.launch.py",
        """
        import launch
        from launch_ros.actions import LifecycleNode, LifecycleTransition
        from lifecycle_msgs.msg import Transition
        def talker(name):
            return LifecycleNode(package="lifecycle", executable="lifecycle_talker", name=name,
                                 namespace="", output="screen")
        def generate_launch_description():
            return launch.LaunchDescription([
                talker("lc_talker"),
                talker("lc_second"),
                LifecycleTransition(lifecycle_node_names=["lc_talker"], transition_ids=[
                    Transition.TRANSITION_CONFIGURE, Transition.TRANSITION_ACTIVATE]),
                LifecycleTransition(lifecycle_node_names=["/lc_second"], transition_ids=[
                    Transition.TRANSITION_ACTIVATE, Transition.TRANSITION_CONFIGURE]),
            ])
        """,
    )
    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"^\[lifecycle_talker-1\] .*on_activate\(\) is called", timeout=60.0)
    pids = refused_then_interrupted(launch, "TRANSITION_ACTIVATE", "/lc_second")
    assert talker_said(launch) == [
        "on_configure() is called (from unconfigured).", "on_activate() is called.",
    ], launch.both()  # fmt: skip
    # lc_second refused activate: its configure, queued after it, was dropped
    assert not [line for line in launch.lines() if line.startswith("[lifecycle_talker-2] ")
                and "() is called" in line], launch.both()  # fmt: skip
    assert_all_gone(pids)


def test_a_launch_test_of_the_managed_talker_passes_under_rosl_launch_test(rosl: Rosl) -> None:
    test = PACKAGES / "lifecycle" / "test" / "managed_talker.launch.py"
    output = rosl.start("launch_test", str(test))

    code = output.finish(120)
    text = output.both()
    assert code == 0, text
    for name in (
        "TestManagedTalker.test_talker_goes_through_its_states",
        "TestManagedTalkerAfterShutdown.test_talker_exits_cleanly",
    ):
        assert re.search(rf"^{name.split('.')[1]} \(.*{name}\) \.\.\. ok$", text, re.M), text
    assert text.count("\nOK") == 2, text
    assert_all_gone(output.pids())
