"""Timers, the tutorial timer_node, Time/Duration, and sim time driven by /clock."""

from __future__ import annotations

import math
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


def test_a_timer_fires_again_and_again_but_never_before_its_period(ros):
    node = ros.Node("ticker")
    clock = node.get_clock()
    stamps: list[int] = []
    created = clock.now().nanoseconds
    timer = node.create_timer(0.05, lambda: stamps.append(clock.now().nanoseconds))
    assert timer.timer_period_ns == 50_000_000

    assert spin_until(node, lambda: len(stamps) >= 10, 20.0), stamps

    # the k-th call comes k periods after the timer was made at the earliest (a late call
    # does not make the next one early); how late it comes depends on the machine's load
    early = [(k, s - created) for k, s in enumerate(stamps, 1) if s - created < k * 50_000_000]
    assert early == [], early


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
    clock = node.get_clock()
    stamps: list[int] = []
    timer = node.create_timer(0.05, lambda: stamps.append(clock.now().nanoseconds))
    assert spin_until(node, lambda: len(stamps) >= 3, 10.0), stamps

    changed = clock.now().nanoseconds
    timer.timer_period_ns = 200_000_000
    assert timer.timer_period_ns == 200_000_000
    stamps.clear()
    assert spin_until(node, lambda: len(stamps) >= 3, 20.0), stamps

    # the k-th call after the change comes k new periods after it at the earliest (at the old
    # 0.05 s period the first would come within about 0.05 s); lateness is the machine's load
    since = [s - changed for s in stamps]
    assert all(t >= k * 200_000_000 for k, t in enumerate(since, 1)), since
    with pytest.raises(ValueError, match="timer_period_ns must be an integer > 0"):
        timer.timer_period_ns = 0
    with pytest.raises(ValueError, match="timer_period_sec must be a finite number > 0"):
        node.create_timer(0.0, lambda: None)


@pytest.mark.parametrize("period", [0.0, -5.0, math.nan, math.inf, 1e300])
def test_create_timer_refuses_a_period_that_is_not_finite_and_positive_as_a_rosl_error(
    ros, period: float
) -> None:
    from rosl.errors import RoslError

    node = ros.Node("bad_period")
    before = list(node.timers)
    with pytest.raises(RoslError, match=r"^create_timer: timer_period_sec must be") as caught:
        node.create_timer(period, lambda: None)

    assert isinstance(caught.value, ValueError)  # what rclpy users catch
    assert repr(period) in str(caught.value)
    assert node.timers == before


# --- the timer's schedule, on a ROS-time clock moved by hand (no wall time involved) --------

S = 1_000_000_000  # one second in ns


def _hand_clock():
    from rosl.node.clock import Clock, ClockType

    clock = Clock(clock_type=ClockType.ROS_TIME)
    clock.set_sim_time(True)  # now_ns() is whatever set_sim_now() last said
    return clock


def _ticks_until(timer, clock, end_ns, step_ns=10_000_000):
    """Move the clock to ``end_ns`` in steps, calling the timer whenever it is ready."""
    ticks = []
    now = clock.now_ns()
    while now < end_ns:
        now += step_ns
        clock.set_sim_now(now)
        if timer.is_ready():
            timer.call()
            ticks.append(now)
    return ticks


@pytest.mark.parametrize("since_last_tick", [0.2, 0.7, 1.4])
def test_a_new_period_starts_at_the_change_not_at_the_last_tick(since_last_tick):
    from rosl.node.timer import Timer

    clock = _hand_clock()
    timer = Timer(None, int(1.5 * S), clock)
    assert _ticks_until(timer, clock, int(1.5 * S)) == [int(1.5 * S)]
    changed = int((1.5 + since_last_tick) * S)
    clock.set_sim_now(changed)
    timer.timer_period_ns = S // 2
    assert not timer.is_ready()
    assert timer.time_until_next_call() == S // 2
    ticks = _ticks_until(timer, clock, changed + int(2.2 * S))
    assert ticks == [changed + k * S // 2 for k in range(1, 5)]


def test_setting_the_period_it_already_has_keeps_the_schedule():
    from rosl.node.timer import Timer

    clock = _hand_clock()
    timer = Timer(None, S // 2, clock)
    ticks = []
    now = 0
    while now < 3 * S:  # code that re-applies its parameter every 0.1 s
        now += S // 10
        clock.set_sim_now(now)
        timer.timer_period_ns = S // 2
        if timer.is_ready():
            timer.call()
            ticks.append(now)
    assert ticks == [k * S // 2 for k in range(1, 7)]


@pytest.mark.parametrize("period", [None, "1s", True, float("nan"), -1])
def test_a_period_in_ns_that_is_no_positive_number_is_a_timer_period_error(period):
    from rosl.node.errors import TimerPeriodError
    from rosl.node.timer import Timer

    timer = Timer(None, S, _hand_clock())
    with pytest.raises(TimerPeriodError):
        timer.timer_period_ns = period


def test_reset_starts_a_full_period_from_now_and_keeps_the_last_call_time():
    from rosl.node.timer import Timer

    clock = _hand_clock()
    timer = Timer(None, S, clock)
    assert _ticks_until(timer, clock, S) == [S]
    clock.set_sim_now(int(1.8 * S))
    timer.reset()
    assert timer.time_until_next_call() == S
    assert timer.time_since_last_call() == int(0.8 * S)
    assert _ticks_until(timer, clock, int(3.9 * S)) == [int(2.8 * S), int(3.8 * S)]


def test_a_changed_schedule_wakes_the_executor_that_waits_for_the_old_one():
    from rosl.node.timer import Timer

    woken: list[int] = []
    clock = _hand_clock()
    timer = Timer(None, 60 * S, clock, lambda: woken.append(clock.now_ns()))
    clock.set_sim_now(S)
    timer.timer_period_ns = S // 20  # an executor asleep until 60 s must look again now
    clock.set_sim_now(2 * S)
    timer.reset()
    assert woken == [S, 2 * S]


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
    assert setter.wait_for_service(timeout_sec=20.0)

    def set_period(value):
        request = SetParameters.Request(
            parameters=[ros.Parameter("timer_period_s", value=value).to_parameter_msg()]
        )
        return setter.call(request, timeout_sec=15.0).results[0]

    asked_ns = time.time_ns()  # the child's log stamps are the same (system) clock
    result = set_period(0.5)
    assert result.successful, result.reason
    child.expect(r"\[timer_node\]: Timer period changed to 0.5 s", stream="err")
    # every tick logged after the change runs at the new period, counted from the change: the
    # k-th comes k * 0.5 s after the request at the earliest (at the old 0.2 s the first would
    # come within about 0.2 s); how late they come depends on the machine's load
    later = [
        child.expect(
            r"\[(\d+)\.(\d{9})\] \[timer_node\]: Tick (\d+) \(period ([\d.]+) s\)$",
            stream="err",
        )
        for _ in range(3)
    ]
    assert [m.group(4) for m in later] == ["0.5"] * 3, [m.group(0) for m in later]
    numbers = [int(m.group(3)) for m in later]
    assert numbers == list(range(numbers[0], numbers[0] + 3)), numbers
    since = [int(m.group(1)) * 1_000_000_000 + int(m.group(2)) - asked_ns for m in later]
    assert all(t >= k * 500_000_000 for k, t in enumerate(since, 1)), since

    refused = set_period(0.0)
    assert not refused.successful
    assert refused.reason == "timer_period_s must be > 0"
    values = getter.call(GetParameters.Request(names=["timer_period_s"]), timeout_sec=15.0)
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
import rosl
from rosgraph_msgs.msg import Clock

rosl.init()
node = rosl.Node("sim_clock")
pub = node.create_publisher(Clock, "/clock", 10)
print("ready", flush=True)
# the same time over and over (42.5 s)
while rosl.ok():
    pub.publish(Clock(clock=rosl.Time(seconds=42, nanoseconds=500_000_000).to_msg()))
    rosl.spin_once(node, timeout_sec=0.05)
"""


def _follows_clock(ros, spawn, node):
    assert node.get_clock().ros_time_is_active
    assert node.get_clock().now().nanoseconds == 0
    spin_for(node, 0.2)
    assert node.get_clock().now().nanoseconds == 0, "sim time moved with no /clock"
    child = spawn(CLOCK)
    child.expect("^ready$")
    assert spin_until(node, lambda: node.get_clock().now().nanoseconds != 0, 20.0)
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


def test_a_sim_time_timer_ticks_with_clock_not_with_wall_time(ros):
    from rosgraph_msgs.msg import Clock

    node = ros.Node("sim_ticker")
    node.set_parameters([ros.Parameter("use_sim_time", value=True)])
    clock = node.get_clock()
    stamps: list[int] = []
    node.create_timer(0.1, lambda: stamps.append(clock.now().nanoseconds))

    spin_for(node, 0.4)
    assert stamps == [], "a sim-time timer ticked while /clock was silent"

    # /clock in lock-step: 0.05 s of sim time a step, the next step only once this one is read
    # and every call it made due has run, so the count does not depend on the machine's speed
    pub = node.create_publisher(Clock, "/clock", 10)
    for step in range(1, 41):
        now_ns = step * 50_000_000
        message = Clock(clock=ros.Time(nanoseconds=now_ns).to_msg())
        assert spin_until(
            node,
            lambda now_ns=now_ns: (
                clock.now().nanoseconds == now_ns and len(stamps) == now_ns // 100_000_000
            ),
            10.0,
            each=lambda message=message: pub.publish(message),
            every=0.5,
        ), (now_ns, clock.now().nanoseconds, stamps)
    spin_for(node, 0.2)  # wall time goes on; sim time does not, so no more calls

    # one call per 0.1 s of sim time, at the /clock time it fell due (2 s of sim time took the
    # wall time the machine needed, with no call on wall time)
    assert stamps == [k * 100_000_000 for k in range(1, 21)], stamps
