"""``rosl topic ...`` against real nodes in other processes, compared with ROS 2's output."""

from __future__ import annotations

import re
import time
from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import PUBLISHER, SUBSCRIPTION
from tests.cli.conftest import Result, assert_user_error, run, timed, wait_graph
from tests.graph.support import Watched

if TYPE_CHECKING:
    from tests.conftest import Processes

# /my_data (the tutorial's MyData, constant values), /chatter (a 200-character string) and
# /numbers (an int32 sequence) at 20 Hz from /talker; /listener reads /pub_in and says so.
SYSTEM = """
import rosl
from std_msgs.msg import Int32MultiArray, String
from tutorial_pkg.msg import MyData

rosl.init([])
talker = rosl.Node("talker")
listener = rosl.Node("listener")
my_data = talker.create_publisher(MyData, "/my_data", 10)
chatter = talker.create_publisher(String, "/chatter", 10)
numbers = talker.create_publisher(Int32MultiArray, "/numbers", 10)
listener.create_subscription(
    MyData, "/pub_in", lambda m: print(f"heard {m.counter} {m.label}", flush=True), 10
)


def tick():
    my_data.publish(MyData(counter=7, value=0.5, label="reading"))
    chatter.publish(String(data="x" * 200))
    numbers.publish(Int32MultiArray(data=[1, 2, 3]))


talker.create_timer(0.05, tick)
executor = rosl.get_global_executor()
executor.add_node(talker)
executor.add_node(listener)
print("ready", flush=True)
executor.spin()
rosl.shutdown()
"""

# argv: node name, topic, type module, type name; publishes a default message at 20 Hz
PUBLISHER_OF = """
import importlib
import sys
import rosl

name, topic, module, type_name = sys.argv[1:5]
msg_type = getattr(importlib.import_module(module), type_name)
rosl.init([])
node = rosl.Node(name)
pub = node.create_publisher(msg_type, topic, 10)
node.create_timer(0.05, lambda: pub.publish(msg_type()))
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

ECHO_ONCE = "counter: 7\nvalue: 0.5\nlabel: reading\n---\n"


@pytest.fixture
def system(processes: Processes) -> Watched:
    child = Watched(processes.python(SYSTEM))
    child.wait_ready()
    wait_graph(lambda g: g.count(PUBLISHER, "/numbers") == 1 and g.count(SUBSCRIPTION, "/pub_in"))
    return child


def test_list_prints_names_types_count_and_verbose_sections_as_ros2(system, processes) -> None:
    names = ["/chatter", "/my_data", "/numbers", "/parameter_events", "/pub_in", "/rosout"]
    assert run(processes, "topic", "list") == Result(0, "\n".join(names) + "\n", "")
    assert run(processes, "topic", "list", "-c") == Result(0, "6\n", "")
    typed = run(processes, "topic", "list", "-t")
    assert typed.out == (
        "/chatter [std_msgs/msg/String]\n"
        "/my_data [tutorial_pkg/msg/MyData]\n"
        "/numbers [std_msgs/msg/Int32MultiArray]\n"
        "/parameter_events [rcl_interfaces/msg/ParameterEvent]\n"
        "/pub_in [tutorial_pkg/msg/MyData]\n"
        "/rosout [rcl_interfaces/msg/Log]\n"
    )
    verbose = run(processes, "topic", "list", "-v")
    assert verbose.out == (
        "Published topics:\n"
        " * /chatter [std_msgs/msg/String] 1 publisher\n"
        " * /my_data [tutorial_pkg/msg/MyData] 1 publisher\n"
        " * /numbers [std_msgs/msg/Int32MultiArray] 1 publisher\n"
        " * /parameter_events [rcl_interfaces/msg/ParameterEvent] 2 publishers\n"
        " * /rosout [rcl_interfaces/msg/Log] 2 publishers\n"
        "\n"
        "Subscribed topics:\n"
        " * /pub_in [tutorial_pkg/msg/MyData] 1 subscriber\n"
        "\n"
    )
    assert verbose.code == 0


def test_info_prints_the_type_and_counts_and_with_v_one_block_per_endpoint(
    system, processes
) -> None:
    assert run(processes, "topic", "info", "/my_data") == Result(
        0, "Type: tutorial_pkg/msg/MyData\nPublisher count: 1\nSubscription count: 0\n", ""
    )
    verbose = run(processes, "topic", "info", "/pub_in", "-v")
    assert verbose.code == 0, verbose.err
    expected = (
        "Type: tutorial_pkg/msg/MyData\n\n"
        "Publisher count: 0\n\n"
        "Subscription count: 1\n\n"
        "Node name: listener\n"
        "Node namespace: /\n"
        "Topic type: tutorial_pkg/msg/MyData\n"
        "Endpoint type: SUBSCRIPTION\n"
        "GID: GID\n"
        "QoS profile:\n"
        "  Reliability: RELIABLE\n"
        "  History (Depth): KEEP_LAST (10)\n"
        "  Durability: VOLATILE\n"
        "  Lifespan: Infinite\n"
        "  Deadline: Infinite\n"
        "  Liveliness: AUTOMATIC\n"
        "  Liveliness lease duration: Infinite\n"
        "Messages received: 0 (lost: 0, wrong type: 0)\n\n"
    )
    gid = r"(?:[0-9a-f]{2}\.){15}[0-9a-f]{2}"
    assert re.fullmatch(re.escape(expected).replace("GID:\\ GID", f"GID: {gid}"), verbose.out)


def test_info_of_an_unknown_topic_is_one_line_naming_the_closest(system, processes) -> None:
    result = run(processes, "topic", "info", "/my_dat")
    assert result.out == ""
    assert assert_user_error(result) == "Unknown topic '/my_dat' (did you mean '/my_data'?)"


def test_type_and_find_print_what_ros2_prints(system, processes) -> None:
    assert run(processes, "topic", "type", "/my_data") == Result(0, "tutorial_pkg/msg/MyData\n", "")
    # find counts subscribed topics too (ros2 asks for every topic name and type)
    found = Result(0, "/my_data\n/pub_in\n", "")
    assert run(processes, "topic", "find", "tutorial_pkg/msg/MyData") == found
    assert run(processes, "topic", "find", "tutorial_pkg/MyData") == found
    assert run(processes, "topic", "find", "-c", "std_msgs/msg/String") == Result(0, "1\n", "")
    assert run(processes, "topic", "find", "std_msgs/msg/Bool") == Result(0, "", "")


def test_type_of_an_unknown_topic_prints_nothing_and_exits_1_as_ros2(processes) -> None:
    assert run(processes, "topic", "type", "/nope") == Result(1, "", "")


def test_echo_once_prints_one_message_as_yaml_then_dashes(system, processes) -> None:
    assert run(processes, "topic", "echo", "/my_data", "--once") == Result(0, ECHO_ONCE, "")
    given_type = run(processes, "topic", "echo", "/my_data", "tutorial_pkg/msg/MyData", "--once")
    assert given_type == Result(0, ECHO_ONCE, "")
    flow = run(processes, "topic", "echo", "/my_data", "--once", "--flow-style")
    assert flow.out == "{counter: 7, value: 0.5, label: reading}\n---\n"


def test_echo_field_and_csv_print_bare_values(system, processes) -> None:
    label = run(processes, "topic", "echo", "/my_data", "--once", "--field", "label")
    assert label == Result(0, "reading\n---\n", "")
    value = run(processes, "topic", "echo", "/my_data", "--once", "--field", "value")
    assert value == Result(0, "0.5\n---\n", "")
    csv = run(processes, "topic", "echo", "/my_data", "--once", "--csv")
    assert csv == Result(0, "7,0.5,reading\n", "")  # ros2 prints no '---' after a CSV line
    # -i puts the message info's numbers first: two timestamps, two sequence numbers
    with_info = run(processes, "topic", "echo", "/my_data", "--once", "--csv", "-i")
    assert re.fullmatch(r"\d{19},\d{19},\d+,\d+,7,0\.5,reading\n", with_info.out), with_info


def test_echo_no_arr_no_str_and_truncation_use_ros2_placeholders(system, processes) -> None:
    no_arr = run(processes, "topic", "echo", "/numbers", "--once", "--no-arr")
    assert no_arr.out == (
        "layout:\n"
        "  dim: '<sequence type: std_msgs/msg/MultiArrayDimension, length: 0>'\n"
        "  data_offset: 0\n"
        "data: '<sequence type: int32, length: 3>'\n"
        "---\n"
    )
    plain = run(processes, "topic", "echo", "/numbers", "--once")
    assert plain.out == "layout:\n  dim: []\n  data_offset: 0\ndata:\n- 1\n- 2\n- 3\n---\n"
    default = run(processes, "topic", "echo", "/chatter", "--once")
    assert default.out == "data: " + "x" * 128 + "...\n---\n"
    short = run(processes, "topic", "echo", "/chatter", "--once", "--truncate-length", "5")
    assert short.out == "data: xxxxx...\n---\n"
    full = run(processes, "topic", "echo", "/chatter", "--once", "--full-length")
    assert full.out == "data: " + "x" * 200 + "\n---\n"
    no_str = run(processes, "topic", "echo", "/chatter", "--once", "--no-str")
    assert no_str.out == "data: '<string length: <200>>'\n---\n"


def test_echo_filter_selects_messages_and_times_out_when_none_pass(system, processes) -> None:
    kept = run(processes, "topic", "echo", "/my_data", "--once", "--filter", "m.counter == 7")
    assert kept == Result(0, ECHO_ONCE, "")
    result, took = timed(
        processes, "topic", "echo", "/my_data", "--filter", "m.counter == 8", "--timeout", "0.5"
    )
    assert result.out == ""
    assert assert_user_error(result) == "no message on /my_data within 0.5 s"
    assert took < 5.0


def test_a_filter_failing_at_run_time_is_one_line_without_traceback(system, processes) -> None:
    echo = run(processes, "topic", "echo", "/my_data", "--once", "--filter", "m.bad")
    assert echo.out == ""
    line = assert_user_error(echo)
    assert line == "--filter: m.bad: AttributeError: 'MyData' object has no attribute 'bad'"
    hz = run(processes, "topic", "hz", "/my_data", "--filter", "m.bad")
    assert hz.out == ""
    assert assert_user_error(hz) == line


def test_echo_with_a_type_other_than_the_publishers_fails_at_once(system, processes) -> None:
    result, took = timed(processes, "topic", "echo", "/my_data", "std_msgs/msg/String")
    assert result.out == ""
    line = assert_user_error(result)
    assert line == (
        "Cannot echo topic '/my_data' as std_msgs/msg/String: it is published as "
        "tutorial_pkg/msg/MyData"
    )
    assert took < 5.0


def test_echo_of_an_unknown_topic_warns_and_names_the_closest(system, processes) -> None:
    result = run(processes, "topic", "echo", "/my_dat")
    assert result.out == ""
    line = assert_user_error(result, "WARNING: topic [/my_dat] does not appear to be published")
    assert "(did you mean '/my_data'?)" in line


def test_echo_with_a_type_waits_for_a_topic_not_yet_published(processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/later", "std_msgs/msg/String", "--once"))
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/later") == 1)  # echo is waiting
    assert echo.child.poll() is None
    talker = Watched(processes.python(PUBLISHER_OF, "late", "/later", "std_msgs.msg", "String"))
    talker.wait_ready()
    assert echo.child.wait(timeout=10) == 0, echo.text("err")
    echo.interrupt()
    assert echo.text("out") == "data: ''\n---"
    assert echo.text("err") == ""


def test_echo_waiting_with_a_type_fails_when_the_publisher_has_another(processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/later", "std_msgs/msg/String"))
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/later") == 1)
    talker = Watched(processes.python(PUBLISHER_OF, "late", "/later", "std_msgs.msg", "Int32"))
    talker.wait_ready()
    assert echo.child.wait(timeout=10) == 1
    echo.interrupt()
    assert "Traceback" not in echo.text("err")
    assert echo.lines("err")[-1] == (
        "Cannot echo topic '/later' as std_msgs/msg/String: it is published as std_msgs/msg/Int32"
    )


def test_hz_prints_ros2s_two_line_report_with_the_true_rate(system, processes) -> None:
    hz = Watched(processes.rosl("topic", "hz", "/my_data"))
    assert hz.wait_for(r"window: \d+$", timeout=10, count=2), hz.text("err")
    hz.interrupt()
    lines = hz.lines()
    assert len(lines) >= 4
    for rate_line, stats_line in zip(lines[0:4:2], lines[1:4:2], strict=True):
        rate = re.fullmatch(r"average rate: (\d+\.\d{3})", rate_line)
        assert rate, lines
        assert 15.0 < float(rate.group(1)) < 25.0  # published at 20 Hz
        stats = re.fullmatch(
            r"\tmin: (\d+\.\d{3})s max: (\d+\.\d{3})s std dev: \d+\.\d{5}s window: (\d+)",
            stats_line,
        )
        assert stats, lines
        assert float(stats.group(1)) <= 0.05 <= float(stats.group(2)) + 0.01
        assert int(stats.group(3)) >= 10
    assert "Traceback" not in hz.text("err")


def test_bw_prints_subscribed_then_ros2s_bandwidth_lines(system, processes) -> None:
    bw = Watched(processes.rosl("topic", "bw", "/my_data"))
    assert bw.wait_for(r"^\tMessage size mean", timeout=10), bw.text("err")
    bw.interrupt()
    lines = bw.lines()
    assert lines[0] == "Subscribed to [/my_data]"
    rate = re.fullmatch(r"(\d+) B/s from (\d+) messages", lines[1])
    assert rate, lines
    # 32 bytes a message (CDR header, int32, float64, string 'reading') at 20 Hz
    assert 480 < int(rate.group(1)) < 800
    assert lines[2] == "\tMessage size mean: 32 B min: 32 B max: 32 B"


def test_pub_once_waits_for_the_subscriber_and_says_how_many_got_it(system, processes) -> None:
    result = run(processes, "topic", "pub", "--once", "/pub_in", "tutorial_pkg/msg/MyData",
                 "{counter: 3, label: hi}")  # fmt: skip
    assert result == Result(
        0,
        "publisher: beginning loop\n"
        "publishing #1: tutorial_pkg.msg.MyData(counter=3, value=0.0, label='hi')\n\n",
        "sent 1 message(s) to 1 matched subscription(s) on /pub_in\n",
    )
    assert system.wait_for(r"^heard 3 hi$", timeout=5)


def test_pub_times_publishes_n_messages_at_the_rate(system, processes) -> None:
    result = run(processes, "topic", "pub", "-t", "4", "-r", "5", "/pub_in",
                 "tutorial_pkg/msg/MyData", "{counter: 4}")  # fmt: skip
    assert result.code == 0, result.err
    assert result.out.count("publishing #") == 4
    assert "publishing #4: tutorial_pkg.msg.MyData(counter=4, value=0.0, label='')\n" in result.out
    assert result.err == "sent 4 message(s) to 1 matched subscription(s) on /pub_in\n"
    assert system.wait_for(r"^heard 4 $", timeout=5, count=4)


def test_pub_rate_spaces_the_messages(system, processes) -> None:
    pub = Watched(processes.rosl("topic", "pub", "-r", "5", "/pub_in", "tutorial_pkg/msg/MyData",
                                 "{counter: 5}"))  # fmt: skip
    assert system.wait_for(r"^heard 5 $", timeout=10)
    first = time.monotonic()
    assert system.wait_for(r"^heard 5 $", timeout=10, count=4)
    took = time.monotonic() - first
    pub.interrupt()
    assert 0.45 < took < 1.5, took  # three periods of 0.2 s
    assert pub.lines()[0] == "publisher: beginning loop"


def test_pub_of_another_type_than_the_subscriptions_is_refused(system, processes) -> None:
    result, took = timed(processes, "topic", "pub", "--once", "/pub_in", "std_msgs/msg/String",
                         "{data: hi}")  # fmt: skip
    assert result.out == ""
    line = assert_user_error(result)
    assert line == (
        "Cannot publish std_msgs/msg/String on /pub_in: its subscriptions expect "
        "tutorial_pkg/msg/MyData"
    )
    assert took < 4.0
    assert not system.matching("^heard")


def test_pub_at_a_rate_warns_once_about_subscriptions_of_another_type(system, processes) -> None:
    pub = Watched(processes.rosl("topic", "pub", "-r", "20", "/pub_in", "std_msgs/msg/String"))
    assert pub.wait_for(r"^publishing #3:", timeout=10), pub.text("err")
    pub.interrupt()
    assert pub.lines("err") == [
        "WARNING: subscriptions on /pub_in expecting tutorial_pkg/msg/MyData will not receive "
        "these std_msgs/msg/String messages"
    ]


def test_pub_of_a_number_for_a_string_field_sends_its_text_as_ros2_does(rosl, domain_id) -> None:
    result = rosl(
        "topic", "pub", "--once", "-w", "0", "/x", "tutorial_pkg/msg/MyData", "{label: 5}"
    )
    assert result.code == 0, result.err
    assert "label='5'" in result.out
    result = rosl("topic", "pub", "--once", "/x", "std_msgs/msg/String", "[1, 2]")
    assert_user_error(result, "must be a YAML mapping")
