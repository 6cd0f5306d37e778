"""Logging: rcutils' console format, levels from --ros-args, throttle/once, and /rosout."""

from __future__ import annotations

import re

from tests.node.helpers import spin_until

LOGGER = """
import time
import rosl

rosl.init()
node = rosl.Node("talker")
log = node.get_logger()
log.info("hello there")
log.debug("a debug line")
log.warning("careful now")
log.error("it broke")
rosl.Node("cam", namespace="/robot/sensors").get_logger().info("from a namespace")
for i in range(20):
    log.info("throttled line", throttle_duration_sec=30.0)
    log.info("once line", once=True)
    log.info("skip-first line", skip_first=True)
    log.info(f"every line {i}")
    time.sleep(0.005)
print("done", flush=True)
rosl.shutdown()
"""

STAMP = r"\[\d+\.\d{9}\]"


def _run(spawn, *args):
    child = spawn(LOGGER, *args)
    child.expect("^done$")
    _, err = child.finish()
    assert child.returncode == 0, err
    return err


def test_log_lines_use_ros2s_console_format_with_the_node_name(spawn):
    err = _run(spawn)

    assert re.search(rf"^\[INFO\] {STAMP} \[talker\]: hello there$", err, re.M), err
    assert re.search(rf"^\[WARN\] {STAMP} \[talker\]: careful now$", err, re.M), err
    assert re.search(rf"^\[ERROR\] {STAMP} \[talker\]: it broke$", err, re.M), err
    stamp = float(re.search(r"\[INFO\] \[(\d+\.\d{9})\] \[talker\]: hello there", err).group(1))
    assert stamp > 1_600_000_000


def test_a_namespaced_nodes_logger_name_uses_dots(spawn):
    err = _run(spawn)
    assert re.search(rf"^\[INFO\] {STAMP} \[robot\.sensors\.cam\]: from a namespace$", err, re.M)


def test_debug_lines_are_hidden_by_default_and_shown_with_log_level_debug(spawn):
    default = _run(spawn)
    debug = _run(spawn, "--ros-args", "--log-level", "debug")

    assert "a debug line" not in default
    assert re.search(rf"^\[DEBUG\] {STAMP} \[talker\]: a debug line$", debug, re.M), debug


def test_a_log_level_for_one_logger_leaves_the_others_alone(spawn):
    err = _run(spawn, "--ros-args", "--log-level", "talker:=error")
    assert "hello there" not in err
    assert "careful now" not in err
    assert re.search(rf"^\[ERROR\] {STAMP} \[talker\]: it broke$", err, re.M)
    assert "from a namespace" in err


def test_throttle_once_and_skip_first_limit_repeated_lines(spawn):
    err = _run(spawn)
    assert len(re.findall(r"\[talker\]: every line \d+$", err, re.M)) == 20
    assert len(re.findall(r"\[talker\]: throttled line$", err, re.M)) == 1
    assert len(re.findall(r"\[talker\]: once line$", err, re.M)) == 1
    assert len(re.findall(r"\[talker\]: skip-first line$", err, re.M)) == 19


def test_log_lines_go_to_stdout_when_rcutils_says_so(spawn, monkeypatch):
    monkeypatch.setenv("RCUTILS_LOGGING_USE_STDOUT", "1")
    child = spawn(LOGGER)
    out, err = child.finish()
    assert re.search(rf"^\[INFO\] {STAMP} \[talker\]: hello there$", out, re.M), out
    assert "hello there" not in err


ROSOUT = """
import rosl
from rcl_interfaces.msg import Log

rosl.init()
node = rosl.Node("rosout_reader")

def on_log(msg):
    if msg.name == "rosout_writer":
        print(f"log level={msg.level} name={msg.name} msg={msg.msg} "
              f"stamp={msg.stamp.sec} function={msg.function}", flush=True)

node.create_subscription(Log, "/rosout", on_log, 100)
print("ready", flush=True)
rosl.spin(node)
"""


def test_each_log_record_is_published_on_rosout(ros, spawn):
    import time

    child = spawn(ROSOUT)
    child.expect("^ready$")
    node = ros.Node("rosout_writer")
    counter = [0]

    def log_something():
        counter[0] += 1
        node.get_logger().warning(f"hello rosout {counter[0]}")

    def heard():
        return child.wait_for(r"^log level=30 name=rosout_writer msg=hello rosout (\d+) "
                              r"stamp=(\d+) function=(\w+)$", timeout=0.0)  # fmt: skip

    match = None

    def got_one():
        nonlocal match
        match = match or heard()
        return match is not None

    assert spin_until(node, got_one, 20.0, each=log_something, every=0.2), child.text
    assert 1 <= int(match.group(1)) <= counter[0]
    assert abs(int(match.group(2)) - time.time()) < 60
    assert match.group(3) == "log_something"


def test_a_custom_console_format_from_rcutils_is_used(spawn, monkeypatch):
    monkeypatch.setenv("RCUTILS_CONSOLE_OUTPUT_FORMAT", "{severity}|{name}|{message}")
    err = _run(spawn)
    assert re.search(r"^INFO\|talker\|hello there$", err, re.M), err


def test_disable_stdout_logs_keeps_log_lines_off_the_console(spawn):
    err = _run(spawn, "--ros-args", "--disable-stdout-logs")
    assert "hello there" not in err
    assert "it broke" not in err


QUIET = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("quiet")
beat = node.create_publisher(String, "heartbeat", 10)

def tick():
    node.get_logger().info("not for rosout")
    beat.publish(String(data="beat"))

node.create_timer(0.05, tick)
print("ready", flush=True)
rosl.spin(node)
"""


def test_disable_rosout_logs_keeps_records_off_rosout(ros, spawn):
    from rcl_interfaces.msg import Log
    from std_msgs.msg import String

    child = spawn(QUIET, "--ros-args", "--disable-rosout-logs")
    child.expect("^ready$")
    node = ros.Node("rosout_checker")
    records: list[Log] = []
    beats: list[str] = []
    node.create_subscription(Log, "/rosout", records.append, 100)
    node.create_subscription(String, "heartbeat", beats.append, 10)

    assert spin_until(node, lambda: len(beats) >= 10, 20.0)
    assert [r for r in records if r.name == "quiet"] == []
    child.expect(r"\[quiet\]: not for rosout", stream="err")
