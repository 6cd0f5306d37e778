"""Services across processes: sync and async calls, timeouts, calls inside callbacks, errors."""

from __future__ import annotations

import threading
import time

import pytest

from tests.node.helpers import spin_until

ADDER = """
import rosl
from example_interfaces.srv import AddTwoInts

rosl.init()
node = rosl.Node("adder")

def add(request, response):
    if request.a < 0:
        raise ValueError("negative numbers are not allowed")
    response.sum = request.a + request.b
    print(f"served {request.a}+{request.b}", flush=True)
    return response

node.create_service(AddTwoInts, "add_two_ints", add)
print("ready", flush=True)
rosl.spin(node)
"""


@pytest.fixture
def adder(spawn):
    child = spawn(ADDER)
    child.expect("^ready$")
    return child


def _client(ros, name="caller"):
    from example_interfaces.srv import AddTwoInts

    node = ros.Node(name)
    client = node.create_client(AddTwoInts, "/add_two_ints")
    assert client.wait_for_service(timeout_sec=20.0), "the adder never appeared in the graph"
    return node, client, AddTwoInts


def test_a_synchronous_call_gets_the_answer_from_another_process(ros, adder):
    _, client, add_two_ints = _client(ros)
    assert client.service_is_ready()

    response = client.call(add_two_ints.Request(a=20, b=22), timeout_sec=15.0)

    assert response.sum == 42
    adder.expect("^served 20\\+22$")


def test_call_async_completes_under_spin_until_future_complete(ros, adder):
    _, client, add_two_ints = _client(ros)
    node = client.node

    future = client.call_async(add_two_ints.Request(a=-5 + 10, b=7))
    ros.spin_until_future_complete(node, future, timeout_sec=15.0)

    assert future.done()
    assert future.exception() is None
    assert future.result().sum == 12


def test_several_async_calls_in_flight_each_get_their_own_answer(ros, adder):
    _, client, add_two_ints = _client(ros)
    node = client.node

    futures = [client.call_async(add_two_ints.Request(a=i, b=1000)) for i in range(5)]
    deadline = time.monotonic() + 20.0
    for future in futures:
        ros.spin_until_future_complete(
            node, future, timeout_sec=max(0.0, deadline - time.monotonic())
        )

    assert [f.result().sum if f.done() else None for f in futures] == [
        1000,
        1001,
        1002,
        1003,
        1004,
    ]


def test_wait_for_service_returns_false_after_its_timeout_when_nobody_serves(ros):
    from example_interfaces.srv import AddTwoInts

    node = ros.Node("hopeful")
    client = node.create_client(AddTwoInts, "no_such_service")
    start = time.monotonic()
    assert client.wait_for_service(timeout_sec=0.5) is False
    assert time.monotonic() - start >= 0.45
    assert client.service_is_ready() is False


def test_a_call_nobody_answers_raises_a_timeout_error_instead_of_hanging(ros):
    from example_interfaces.srv import AddTwoInts

    from rosl.errors import RoslError

    node = ros.Node("impatient")
    client = node.create_client(AddTwoInts, "nobody_home")
    outcome: dict[str, object] = {}

    def call() -> None:
        try:
            outcome["result"] = client.call(AddTwoInts.Request(a=1, b=2), timeout_sec=0.5)
        except Exception as err:  # inspected below
            outcome["error"] = err

    worker = threading.Thread(target=call, daemon=True)
    worker.start()
    worker.join(timeout=10.0)

    assert not worker.is_alive(), "Client.call(timeout_sec=0.5) did not return within 10 s"
    error = outcome.get("error")
    assert isinstance(error, TimeoutError), outcome
    assert isinstance(error, RoslError)
    assert "/nobody_home" in str(error)
    assert client._pending == {}, "the timed-out request is still pending"


def test_a_synchronous_call_inside_a_subscription_callback_works(ros, adder):
    from std_msgs.msg import Int32

    node, client, add_two_ints = _client(ros, "relay")
    sums: list[int] = []
    heard: list[int] = []

    def on_trigger(msg):
        heard.append(msg.data)
        sums.append(client.call(add_two_ints.Request(a=msg.data, b=100), timeout_sec=15.0).sum)

    node.create_subscription(Int32, "trigger", on_trigger, 10)
    # another subscription whose messages arrive while the call waits must not be lost
    others: list[int] = []
    node.create_subscription(Int32, "other", lambda m: others.append(m.data), 10)
    trigger = node.create_publisher(Int32, "trigger", 10)
    other = node.create_publisher(Int32, "other", 10)

    assert spin_until(node, lambda: bool(sums), 20.0, each=lambda: trigger.publish(Int32(data=7)))
    assert sums[0] == 107
    assert all(s == h + 100 for s, h in zip(sums, heard, strict=True))
    assert spin_until(node, lambda: bool(others), 5.0, each=lambda: other.publish(Int32(data=3)))
    assert set(others) == {3}


def test_a_server_callback_that_raises_fails_the_call_at_once_and_keeps_serving(ros, adder):
    from rosl.node.client import ServiceFailedError

    _, client, add_two_ints = _client(ros)

    # a long timeout: the failure must come as the server's answer, not as the wait running out
    with pytest.raises(ServiceFailedError) as failed:
        client.call(add_two_ints.Request(a=-1, b=1), timeout_sec=30.0)
    assert str(failed.value) == (
        "service /add_two_ints failed: ValueError: negative numbers are not allowed"
    )
    assert failed.value.error == "ValueError: negative numbers are not allowed"
    adder.expect(
        r"^\[ERROR\] \[\d+\.\d{9}\] \[adder\]: exception in callback for /add_two_ints: "
        r"ValueError: negative numbers are not allowed",
        stream="err",
    )

    assert client.call(add_two_ints.Request(a=2, b=3), timeout_sec=15.0).sum == 5
    assert adder.popen.poll() is None, "the server process died"


def test_call_async_of_a_failing_server_gives_a_failed_future_as_rclpy_code_expects(ros, adder):
    from rosl.node.client import ServiceFailedError

    node, client, add_two_ints = _client(ros)
    future = client.call_async(add_two_ints.Request(a=-7, b=1))
    ros.spin_until_future_complete(node, future, timeout_sec=30.0)

    assert future.done()
    assert isinstance(future.exception(), ServiceFailedError)
    with pytest.raises(ServiceFailedError, match="ValueError: negative numbers are not allowed"):
        future.result()
    # the next request of the same client is answered as usual
    future = client.call_async(add_two_ints.Request(a=1, b=1))
    ros.spin_until_future_complete(node, future, timeout_sec=15.0)
    assert future.result().sum == 2


def test_a_service_callback_returning_the_wrong_type_is_reported(ros, spawn):
    from std_srvs.srv import Trigger

    from rosl.node.client import ServiceFailedError

    child = spawn(
        """
        import rosl
        from std_srvs.srv import Trigger

        rosl.init()
        node = rosl.Node("sloppy")
        node.create_service(Trigger, "trigger", lambda request, response: None)
        print("ready", flush=True)
        rosl.spin(node)
        """
    )
    child.expect("^ready$")
    node = ros.Node("asker")
    client = node.create_client(Trigger, "/trigger")
    assert client.wait_for_service(timeout_sec=20.0)
    with pytest.raises(ServiceFailedError, match=r"failed: TypeError: .*Trigger_Response"):
        client.call(Trigger.Request(), timeout_sec=30.0)
    child.expect(
        r"\[ERROR\] .*\[sloppy\]: exception in callback for /trigger: TypeError: .*"
        r"std_srvs/srv/Trigger_Response",
        stream="err",
    )


def test_call_async_rejects_a_request_of_the_wrong_type(ros):
    from example_interfaces.srv import AddTwoInts
    from std_srvs.srv import Trigger

    node = ros.Node("confused")
    client = node.create_client(AddTwoInts, "add_two_ints")
    with pytest.raises(TypeError, match="AddTwoInts"):
        client.call_async(Trigger.Request())


def test_spin_until_future_complete_returns_after_its_timeout_if_nothing_completes(ros):
    node = ros.Node("waiter")
    future = ros.Future()
    start = time.monotonic()
    ros.spin_until_future_complete(node, future, timeout_sec=0.3)
    assert not future.done()
    assert 0.25 <= time.monotonic() - start < 20.0  # returned, not hung
    future.set_result(3)
    ros.spin_until_future_complete(node, future, timeout_sec=15.0)
    assert future.result() == 3
