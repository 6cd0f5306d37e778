"""What happens when user code goes wrong: callbacks raising, wrong types, no init."""

from __future__ import annotations

import re

import pytest

from tests.node.helpers import spin_until

DIVIDER = """
import rosl
from std_msgs.msg import Int32

rosl.init()
node = rosl.Node("divider")

def on_number(msg):
    print("got", 100 // msg.data, flush=True)

node.create_subscription(Int32, "numbers", on_number, 10)
print("ready", flush=True)
rosl.spin(node)
"""


def test_a_raising_callback_is_logged_with_the_node_name_and_the_node_keeps_spinning(ros, spawn):
    from std_msgs.msg import Int32

    child = spawn(DIVIDER)
    child.expect("^ready$")
    node = ros.Node("feeder")
    pub = node.create_publisher(Int32, "numbers", 10)
    pattern = (
        r"^\[ERROR\] \[\d+\.\d{9}\] \[divider\]: exception in callback for /numbers: "
        r"ZeroDivisionError: integer division or modulo by zero \(at <string>:\d+ in on_number\)"
    )

    assert spin_until(
        node,
        lambda: child.wait_for(pattern, stream="err", timeout=0.0) is not None,
        20.0,
        each=lambda: pub.publish(Int32(data=0)),
    ), child.text
    assert spin_until(
        node,
        lambda: child.wait_for("^got 25$", timeout=0.0) is not None,
        20.0,
        each=lambda: pub.publish(Int32(data=4)),
    ), child.text
    assert child.popen.poll() is None
    _, err = child.stop()
    assert child.returncode == 0
    assert "Traceback (most recent call last):" in err  # the user's frames are shown too
    assert re.search(r'File "<string>", line \d+, in on_number', err)


def test_a_raising_timer_callback_is_logged_and_the_timer_keeps_firing(ros, capfd):
    node = ros.Node("flaky_timer")
    calls: list[int] = []

    def tick():
        calls.append(1)
        if len(calls) == 1:
            raise RuntimeError("first tick fails")

    node.create_timer(0.02, tick)
    assert spin_until(node, lambda: len(calls) >= 3, 5.0)
    err = capfd.readouterr().err
    assert re.search(
        r"\[ERROR\] \[\d+\.\d{9}\] \[flaky_timer\]: exception in callback for timer: "
        r"RuntimeError: first tick fails",
        err,
    ), err


def test_with_callback_errors_raise_spin_propagates_the_exception(domain_id):
    import rosl

    rosl.init([], callback_errors="raise")
    try:
        node = rosl.Node("strict_node")
        executor = rosl.SingleThreadedExecutor()

        def explode():
            raise ValueError("boom from a timer")

        node.create_timer(0.02, explode)
        node.create_timer(5.0, executor.shutdown)  # a bound, should the exception not come
        with pytest.raises(ValueError, match="boom from a timer"):
            rosl.spin(node, executor)
    finally:
        rosl.shutdown()
    rosl.init([])
    try:
        assert rosl.get_default_context().callback_errors == "log"
    finally:
        rosl.shutdown()


def test_with_callback_errors_raise_a_subscription_error_stops_spin_in_a_script(spawn, ros):
    from std_msgs.msg import Int32

    child = spawn(
        """
        import rosl
        from std_msgs.msg import Int32

        rosl.init(callback_errors="raise")
        node = rosl.Node("strict_divider")
        node.create_subscription(Int32, "numbers", lambda m: print(100 // m.data), 10)
        print("ready", flush=True)
        try:
            rosl.spin(node)
        except ZeroDivisionError as err:
            print("spin raised", type(err).__name__, flush=True)
        rosl.shutdown()
        """
    )
    child.expect("^ready$")
    node = ros.Node("feeder2")
    pub = node.create_publisher(Int32, "numbers", 10)
    assert spin_until(
        node,
        lambda: child.wait_for("^spin raised ZeroDivisionError$", timeout=0.0) is not None,
        20.0,
        each=lambda: pub.publish(Int32(data=0)),
    ), child.text
    child.finish()
    assert child.returncode == 0


def test_creating_a_node_before_init_raises_a_clear_error(domain_id):
    import rosl
    from rosl.node.context import Context
    from rosl.node.errors import NotInitializedError

    with pytest.raises(NotInitializedError, match=re.escape("call rosl.init() (rclpy.init())")):
        rosl.Node("too_early", context=Context())
    assert issubclass(NotInitializedError, rosl.RoslError)


def test_a_script_creating_a_node_before_init_fails_with_the_message(spawn):
    child = spawn(
        """
        import rosl
        node = rosl.Node("too_early")
        print("created", flush=True)
        """
    )
    out, err = child.finish()
    assert child.returncode != 0
    assert "created" not in out
    assert "call rosl.init() (rclpy.init()) before creating nodes" in err


def test_creating_endpoints_with_something_that_is_not_a_message_class_is_a_type_error(ros):
    node = ros.Node("bad_types")
    with pytest.raises(TypeError, match="message class"):
        node.create_publisher(dict, "x", 10)
    with pytest.raises(TypeError, match="service class"):
        node.create_client(dict, "x")
    with pytest.raises(TypeError, match="QoSProfile or a history depth"):
        node.create_publisher("std_msgs/msg/String", "x", "ten")


def test_two_nodes_with_the_same_name_get_a_warning(ros, spawn, capfd):
    child = spawn(
        """
        import rosl
        rosl.init()
        node = rosl.Node("twin")
        print("ready", flush=True)
        rosl.spin(node)
        """
    )
    child.expect("^ready$")
    node = ros.Node("twin")
    warning = r"\[WARN\] \[\d+\.\d{9}\] \[twin\]: another node is also named /twin"
    seen: list[str] = []

    def warned() -> bool:
        seen.append(capfd.readouterr().err)
        return bool(re.search(warning, "".join(seen)))

    assert spin_until(node, warned, 20.0), "".join(seen)
    child.expect(warning, stream="err")
