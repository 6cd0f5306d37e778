"""Timers, the tutorial timer_node, Time/Duration, and sim time driven by /clock."""

from __future__ import annotations

import sys
import time

import pytest

from tests.conftest import REPO
from tests.node.helpers import spin_for, spin_until

# --- Time and Duration (no bus) ----------------------------------------------------------------


def test_time_and_duration_arithmetic_in_integer_nanoseconds():
    from rosl import ClockType, Duration, Time

    start = Time(seconds=1.5, clock_type=ClockType.ROS_TIME)
    step = Duration(seconds=0.25)

    assert (start + step).nanoseconds == 1_750_000_000
    assert (start - step).nanoseconds == 1_250_000_000
    assert (start + step) - start == step
    assert isinstance((start + step) - start, Duration)
    assert (start + step).clock_type is ClockType.ROS_TIME
    assert start < start + step
    assert Duration(seconds=1) > Duration(nanoseconds=999_999_999)
    assert step * 4 == Duration(seconds=1)
    assert Duration(seconds=1) - Duration(seconds=3) == Duration(seconds=-2)
    assert Time(seconds=2, nanoseconds=5).seconds_nanoseconds() == (2, 5)
    with pytest.raises(TypeError):
        _ = Time(seconds=1, clock_type=ClockType.SYSTEM_TIME) - start
    with pytest.raises(ValueError, match="negative"):
        Time(nanoseconds=-1)


def test_time_and_duration_round_trip_through_messages(ros):
    from rosl import ClockType, Duration, Time

    stamp = Time(seconds=1_700_000_000, nanoseconds=123_456_789, clock_type=ClockType.ROS_TIME)
    msg = stamp.to_msg()
    assert msg.__msgtype__ == "builtin_interfaces/msg/Time"
    assert (msg.sec, msg.nanosec) == (1_700_000_000, 123_456_789)
    assert Time.from_msg(msg) == stamp

    span = Duration(seconds=2.5)
    dmsg = span.to_msg()
    assert dmsg.__msgtype__ == "builtin_interfaces/msg/Duration"
    assert (dmsg.sec, dmsg.nanosec) == (2, 500_000_000)
    assert Duration.from_msg(dmsg) == span
    negative = Duration(nanoseconds=-1).to_msg()
    assert (negative.sec, negative.nanosec) == (-1, 999_999_999)
    assert Duration.from_msg(negative) == Duration(nanoseconds=-1)


def test_a_duration_plus_a_time_is_the_same_time_as_time_plus_duration():
    from rosl import ClockType, Duration, Time

    start = Time(seconds=1.5, clock_type=ClockType.ROS_TIME)
    step = Duration(seconds=0.25)
    total = step + start
    assert isinstance(total, Time), f"Duration + Time gave {total!r}"
    assert total == start + step


def test_a_nodes_clock_reads_ros_time_close_to_the_system_clock(ros):
    from rosl import ClockType

    node = ros.Node("clocked")
    now = node.get_clock().now()
    assert now.clock_type is ClockType.ROS_TIME
    assert abs(now.nanoseconds - time.time_ns()) < 5_000_000_000


# --- timers ------------------------------------------------------------------------------------


def test_a_timer_fires_at_roughly_its_period(ros):
    node = ros.Node("ticker")
    ticks: list[int] = []
    timer = node.create_timer(0.05, lambda: ticks.append(1))
    assert timer.timer_period_ns == 50_000_000

    spin_for(node, 1.0)

    assert 8 <= len(ticks) <= 25, len(ticks)


def test_a_cancelled_timer_stops_and_reset_starts_it_again(ros):
    node = ros.Node("pausable")
    ticks: list[int] = []
    timer = node.create_timer(0.05, lambda: ticks.append(1))
    assert spin_until(node, lambda: len(ticks) >= 3, 5.0)

    timer.cancel()
    assert timer.is_canceled()
    assert timer.time_until_next_call() is None
    stopped_at = len(ticks)
    spin_for(node, 0.4)
    assert len(ticks) == stopped_at

    timer.reset()
    assert not timer.is_canceled()
    assert spin_until(node, lambda: len(ticks) >= stopped_at + 3, 5.0)


def test_destroying_a_timer_stops_it_for_good(ros):
    node = ros.Node("destroyer")
    ticks: list[int] = []
    timer = node.create_timer(0.05, lambda: ticks.append(1))
    assert spin_until(node, lambda: len(ticks) >= 2, 5.0)
    assert node.destroy_timer(timer)
    count = len(ticks)
    spin_for(node, 0.3)
    assert len(ticks) == count
    assert timer not in node.timers


def test_changing_timer_period_ns_takes_effect(ros):
    node = ros.Node("retimed")
    ticks: list[int] = []
    timer = node.create_timer(0.05, lambda: ticks.append(1))
    spin_for(node, 0.6)
    fast = len(ticks)

    timer.timer_period_ns = 200_000_000
    assert timer.timer_period_ns == 200_000_000
    ticks.clear()
    spin_for(node, 1.0)
    slow = len(ticks)

    assert 5 <= fast <= 16, fast
    assert 2 <= slow <= 7, slow
    with pytest.raises(ValueError, match="greater than 0"):
        timer.timer_period_ns = 0
    with pytest.raises(ValueError, match="greater than 0"):
        node.create_timer(0.0, lambda: None)


def _timer_node(spawn, period="0.2"):
    return spawn.command(
        [
            sys.executable, "-m", "rosl.pkg.entry",
            str(REPO / "examples" / "tutorial_pkg"), "tutorial_pkg.timer_node:main", "timer_node",
            "--ros-args", "-p", f"timer_period_s:={period}",
        ]
    )  # fmt: skip


def test_the_tutorial_timer_node_changes_period_live_and_refuses_zero(ros, spawn):
    from rcl_interfaces.srv import GetParameters, SetParameters

    child = _timer_node(spawn)
    child.expect(r"\[INFO\] \[\d+\.\d{9}\] \[timer_node\]: Timer period: 0.2 s", stream="err")
    child.expect(r"\[timer_node\]: Tick 1 \(period 0.2 s\)$", stream="err")
    child.expect(r"\[timer_node\]: Tick 3 \(period 0.2 s\)$", stream="err")

    node = ros.Node("tuner")
    setter = node.create_client(SetParameters, "/timer_node/set_parameters")
    getter = node.create_client(GetParameters, "/timer_node/get_parameters")
    assert setter.wait_for_service(timeout_sec=8.0)

    def set_period(value):
        request = SetParameters.Request(
            parameters=[ros.Parameter("timer_period_s", value=value).to_parameter_msg()]
        )
        return setter.call(request, timeout_sec=5.0).results[0]

    result = set_period(0.5)
    assert result.successful, result.reason
    child.expect(r"\[timer_node\]: Timer period changed to 0.5 s", stream="err")
    first = child.expect(r"\[timer_node\]: Tick (\d+) \(period 0.5 s\)$", stream="err")
    # loose: at 0.5 s about 3 ticks in 1.6 s (at the old 0.2 s it would be about 8)
    deadline = time.monotonic() + 1.6
    later = []
    while (remaining := deadline - time.monotonic()) > 0:
        match = child.wait_for(
            r"\[timer_node\]: Tick (\d+) \(period ([\d.]+) s\)$", stream="err", timeout=remaining
        )
        if match is not None:
            later.append((int(match.group(1)), match.group(2)))
    assert all(period == "0.5" for _, period in later), later
    assert 1 <= len(later) <= 5, later
    assert [n for n, _ in later] == list(
        range(int(first.group(1)) + 1, int(first.group(1)) + 1 + len(later))
    )

    refused = set_period(0.0)
    assert not refused.successful
    assert refused.reason == "timer_period_s must be > 0"
    values = getter.call(GetParameters.Request(names=["timer_period_s"]), timeout_sec=5.0)
    assert values.values[0].double_value == 0.5
    child.expect(r"\[timer_node\]: Tick \d+ \(period 0.5 s\)$", stream="err")

    _, err = child.stop()
    assert child.returncode == 0, err
    assert "Traceback" not in err


def test_the_tutorial_timer_node_reads_an_integer_period_as_a_double(spawn):
    child = _timer_node(spawn, "1")
    child.expect(r"\[timer_node\]: Timer period: 1.0 s", stream="err")


# --- sim time ------------------------------------------------------------------------------

CLOCK = """
import sys, time
import rosl
from rosgraph_msgs.msg import Clock

rosl.init()
node = rosl.Node("sim_clock")
pub = node.create_publisher(Clock, "/clock", 10)
mode = sys.argv[1]
print("ready", flush=True)
if mode == "fixed":
    # the same time over and over (42.5 s)
    while rosl.ok():
        pub.publish(Clock(clock=rosl.Time(seconds=42, nanoseconds=500_000_000).to_msg()))
        rosl.spin_once(node, timeout_sec=0.05)
else:
    # steps of 0.05 s of sim time every 0.02 s of wall time (2.5x faster than real time)
    step = 0
    while rosl.ok():
        step += 1
        pub.publish(Clock(clock=rosl.Time(nanoseconds=step * 50_000_000).to_msg()))
        rosl.spin_once(node, timeout_sec=0.02)
"""


def _follows_clock(ros, spawn, node):
    assert node.get_clock().ros_time_is_active
    assert node.get_clock().now().nanoseconds == 0
    spin_for(node, 0.2)
    assert node.get_clock().now().nanoseconds == 0, "sim time moved with no /clock"
    child = spawn(CLOCK, "fixed")
    child.expect("^ready$")
    assert spin_until(node, lambda: node.get_clock().now().nanoseconds != 0, 8.0)
    assert node.get_clock().now().nanoseconds == 42_500_000_000


def test_a_node_started_with_use_sim_time_reads_zero_until_clock_then_follows_it(ros, spawn):
    node = ros.Node("sim_node", cli_args=["--ros-args", "-p", "use_sim_time:=true"])
    assert node.get_parameter("use_sim_time").value is True
    _follows_clock(ros, spawn, node)


def test_setting_use_sim_time_at_run_time_makes_the_clock_follow_clock(ros, spawn):
    node = ros.Node("sim_later")
    assert node.get_clock().now().nanoseconds > 0
    [result] = node.set_parameters([ros.Parameter("use_sim_time", value=True)])
    assert result.successful
    _follows_clock(ros, spawn, node)
    node.set_parameters([ros.Parameter("use_sim_time", value=False)])
    assert not node.get_clock().ros_time_is_active
    assert node.get_clock().now().nanoseconds > 1_000_000_000_000_000_000


def test_a_sim_time_timer_ticks_with_clock_not_with_wall_time(ros, spawn):
    node = ros.Node("sim_ticker")
    node.set_parameters([ros.Parameter("use_sim_time", value=True)])
    stamps: list[int] = []
    node.create_timer(0.1, lambda: stamps.append(node.get_clock().now().nanoseconds))

    spin_for(node, 0.4)
    assert stamps == [], "a sim-time timer ticked while /clock was silent"

    child = spawn(CLOCK, "steps")
    child.expect("^ready$")
    assert spin_until(node, lambda: node.get_clock().now().nanoseconds >= 2_000_000_000, 10.0)
    ticks = [s for s in stamps if s <= 2_000_000_000]

    # 20 ticks in 2 s of sim time (0.8 s of wall time, where a wall timer would tick ~8 times)
    assert 12 <= len(ticks) <= 20, ticks
    assert all(s % 50_000_000 == 0 for s in ticks), "ticks ran between /clock messages"
    assert ticks == sorted(set(ticks))
    assert all(s >= 100_000_000 * (i + 1) for i, s in enumerate(ticks)), ticks
