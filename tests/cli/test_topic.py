"""``rosl topic ...`` against real nodes in other processes, compared with ROS 2's output."""

from __future__ import annotations

import re
import signal
import time
from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import PUBLISHER, SUBSCRIPTION
from tests.cli.conftest import Result, assert_user_error, run, timed, wait_graph
from tests.conftest import ChildOutput
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
        "  Liveliness lease duration: Infinite\n\n"
    )  # ros2 humble's block exactly: no line of rosl's own
    gid = r"(?:[0-9a-f]{2}\.){15}[0-9a-f]{2}"
    assert re.fullmatch(re.escape(expected).replace("GID:\\ GID", f"GID: {gid}"), verbose.out)
    # rosl's counters only on request
    stats = run(processes, "topic", "info", "/pub_in", "-v", "--stats")
    assert stats.out.endswith(
        "  Liveliness lease duration: Infinite\n"
        "Messages received: 0 (lost: 0, dropped: 0, wrong type: 0)\n\n"
    )


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
    assert took < 20.0  # gave up after its --timeout, did not wait on


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
    assert took < 20.0  # refused from the graph, did not wait on for messages


def test_echo_of_a_topic_of_two_types_warns_once_of_the_other_publisher(processes) -> None:
    # a String and an Int32 publisher on /mix: echo as String shows the strings and names
    # the other publisher once (rclpy warns of an incompatible type too)
    for name, module, type_name in (("strings", "std_msgs.msg", "String"),
                                    ("numbers", "std_msgs.msg", "Int32")):  # fmt: skip
        processes.python(PUBLISHER_OF, name, "/mix", module, type_name)
    wait_graph(lambda g: g.count(PUBLISHER, "/mix") == 2)
    echo = ChildOutput(processes.rosl("topic", "echo", "/mix", "std_msgs/msg/String"))
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and not (
        "another type" in echo.text["err"] and echo.text["out"].count("data: ''") >= 40
    ):
        echo._read(0.05)
    echo.popen.send_signal(signal.SIGINT)
    echo.popen.wait(30.0)
    echo.pump()
    assert echo.text["out"].count("data: ''") >= 40, echo.text
    warnings = [line for line in echo.text["err"].splitlines() if "another type" in line]
    assert len(warnings) == 1, echo.text["err"]
    assert "from /numbers (std_msgs/msg/Int32)" in warnings[0]


def test_echo_waits_a_little_for_a_publisher_that_answers_late(processes) -> None:
    # the talker is stopped while echo asks who is there, so the query looks complete with
    # nobody in it; it goes on 0.6 s after echo started: echo still finds the topic
    talker = ChildOutput(
        processes.python(PUBLISHER_OF, "late_talker", "/late", "std_msgs.msg", "String")
    )
    deadline = time.monotonic() + 30.0
    while "ready" not in talker.text["out"] and time.monotonic() < deadline:
        talker._read(0.05)
    talker.popen.send_signal(signal.SIGSTOP)
    try:
        echo = processes.rosl("topic", "echo", "/late", "--once", env={"NO_COLOR": "1"})
        time.sleep(0.6)
    finally:
        talker.popen.send_signal(signal.SIGCONT)
    out, err = echo.communicate(timeout=30.0)
    assert (echo.returncode, out, err) == (0, "data: ''\n---\n", "")


def test_echo_of_an_unknown_topic_warns_and_names_the_closest(system, processes) -> None:
    result = run(processes, "topic", "echo", "/my_dat")
    assert result.out == "WARNING: topic [/my_dat] does not appear to be published yet\n"
    assert assert_user_error(result) == (
        "Could not determine the type for the passed topic (did you mean '/my_data'?)"
    )


def test_echo_with_no_publisher_prints_ros2s_warning_and_error(processes) -> None:
    result = run(processes, "topic", "echo", "/this_topic_has_no_pub")
    assert result == Result(
        1,
        "WARNING: topic [/this_topic_has_no_pub] does not appear to be published yet\n",
        "Could not determine the type for the passed topic\n",
    )


def test_echo_with_a_type_waits_for_a_topic_not_yet_published(processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/later", "std_msgs/msg/String", "--once"))
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/later") == 1)  # echo is waiting
    assert echo.child.poll() is None
    talker = Watched(processes.python(PUBLISHER_OF, "late", "/later", "std_msgs.msg", "String"))
    talker.wait_ready()
    assert echo.child.wait(timeout=30) == 0, echo.text("err")
    echo.interrupt()
    assert echo.text("out") == "data: ''\n---"
    assert echo.text("err") == ""


def test_echo_waiting_with_a_type_fails_when_the_publisher_has_another(processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/later", "std_msgs/msg/String"))
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/later") == 1)
    talker = Watched(processes.python(PUBLISHER_OF, "late", "/later", "std_msgs.msg", "Int32"))
    talker.wait_ready()
    assert echo.child.wait(timeout=30) == 1
    echo.interrupt()
    assert "Traceback" not in echo.text("err")
    assert echo.lines("err")[-1] == (
        "Cannot echo topic '/later' as std_msgs/msg/String: it is published as std_msgs/msg/Int32"
    )


def test_hz_prints_ros2s_two_line_report_with_the_true_rate(system, processes) -> None:
    hz = Watched(processes.rosl("topic", "hz", "/my_data"))
    assert hz.wait_for(r"window: \d+$", timeout=30, count=2), hz.text("err")
    hz.interrupt()
    lines = hz.lines()
    assert len(lines) >= 4
    for rate_line, stats_line in zip(lines[0:4:2], lines[1:4:2], strict=True):
        rate = re.fullmatch(r"average rate: (\d+\.\d{3})", rate_line)
        assert rate, lines
        measured = float(rate.group(1))
        # published at 20 Hz: a loaded machine delays (and its timer then skips) ticks, and
        # bunches receive times, so only a wide band; a wrong unit or count leaves it
        assert 5.0 < measured < 45.0, lines
        stats = re.fullmatch(
            r"\tmin: (\d+\.\d{3})s max: (\d+\.\d{3})s std dev: \d+\.\d{5}s window: (\d+)",
            stats_line,
        )
        assert stats, lines
        low, high, window = float(stats.group(1)), float(stats.group(2)), int(stats.group(3))
        assert low - 0.001 <= 1 / measured <= high + 0.001, lines  # the mean is in min..max
        # a report comes once a second of messages: the window spans at least that
        assert window / measured >= 0.99, lines
    assert "Traceback" not in hz.text("err")


def test_bw_prints_subscribed_then_ros2s_bandwidth_lines(system, processes) -> None:
    bw = Watched(processes.rosl("topic", "bw", "/my_data"))
    assert bw.wait_for(r"^\tMessage size mean", timeout=30), bw.text("err")
    bw.interrupt()
    lines = bw.lines()
    assert lines[0] == "Subscribed to [/my_data]"
    rate = re.fullmatch(r"(\d+) B/s from (\d+) messages", lines[1])
    assert rate, lines
    # 32 bytes a message (CDR header, int32, float64, string 'reading') at 20 Hz, so about
    # 640 B/s: a wide band, as a loaded machine delays ticks and bunches receive times (the
    # first report divides by the time since the first message read); bits for bytes leave it
    assert 32 * 5 < int(rate.group(1)) < 32 * 100, lines
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
    assert system.wait_for(r"^heard 3 hi$", timeout=15)


def test_pub_times_publishes_n_messages_at_the_rate(system, processes) -> None:
    result = run(processes, "topic", "pub", "-t", "4", "-r", "5", "/pub_in",
                 "tutorial_pkg/msg/MyData", "{counter: 4}")  # fmt: skip
    assert result.code == 0, result.err
    assert result.out.count("publishing #") == 4
    assert "publishing #4: tutorial_pkg.msg.MyData(counter=4, value=0.0, label='')\n" in result.out
    assert result.err == "sent 4 message(s) to 1 matched subscription(s) on /pub_in\n"
    assert system.wait_for(r"^heard 4 $", timeout=15, count=4)


def test_pub_rate_spaces_the_messages(ros, processes) -> None:
    from std_msgs.msg import Header

    from tests.node.helpers import spin_until

    node = ros.Node("stamp_reader")
    stamps: list[int] = []
    node.create_subscription(
        Header, "/stamped", lambda m: stamps.append(m.stamp.sec * 10**9 + m.stamp.nanosec), 10
    )
    # -w 1: the first message goes out once this subscription is matched, so none is missed
    pub = Watched(processes.rosl("topic", "pub", "-r", "5", "-w", "1", "--max-wait-time-secs",
                                 "30", "/stamped", "std_msgs/msg/Header", "{stamp: now}"))  # fmt: skip
    assert spin_until(node, lambda: len(stamps) >= 4, 30.0), (stamps, pub.text("err"))
    pub.interrupt()
    # each message is stamped as it is built: the k-th no earlier than k periods of 0.2 s after
    # the first (a loaded machine only makes them later, then catches up)
    since = [s - stamps[0] for s in stamps[:4]]
    assert all(t >= k * 200_000_000 - 1_000_000 for k, t in enumerate(since)), since
    # ros2's "Waiting for at least 1 matching subscription(s)..." comes first when the
    # subscription is not matched yet (a loaded machine), then the loop begins
    lines = [line for line in pub.lines() if not line.startswith("Waiting for at least 1 ")]
    assert lines[0] == "publisher: beginning loop"


def test_pub_of_another_type_than_the_subscriptions_is_refused(system, processes) -> None:
    result, took = timed(processes, "topic", "pub", "--once", "--max-wait-time-secs", "30",
                         "/pub_in", "std_msgs/msg/String", "{data: hi}")  # fmt: skip
    assert result.out == ""
    line = assert_user_error(result)
    assert line == (
        "Cannot publish std_msgs/msg/String on /pub_in: its subscriptions expect "
        "tutorial_pkg/msg/MyData"
    )
    assert took < 20.0  # refused at once, not after waiting 30 s for a matching subscription
    assert not system.matching("^heard")


def test_pub_at_a_rate_warns_once_about_subscriptions_of_another_type(system, processes) -> None:
    pub = Watched(processes.rosl("topic", "pub", "-r", "20", "/pub_in", "std_msgs/msg/String"))
    assert pub.wait_for(r"^publishing #3:", timeout=30), pub.text("err")
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


def test_pub_of_a_type_with_a_fixed_array_too_large_to_build_is_one_line(
    rosl, make_package, domain_id
) -> None:
    make_package("huge_pkg", {"msg/Huge.msg": "int32 a\nint32[100000000000] big\n"})

    result = rosl("topic", "pub", "--once", "-w", "0", "/x", "huge_pkg/msg/Huge")

    assert result.out == ""
    assert assert_user_error(result) == (
        "src/huge_pkg/msg/Huge.msg:2:7: fixed array 'int32[100000000000]' is too large: "
        "100000000000 elements, at most 67108864 for numbers (use a sequence 'int32[]' for "
        "big data)"
    )


# --- ros2cli (humble) test suites' expectations ------------------------------------------------

# test_msgs' BoundedSequences and Defaults, cut down (the same field kinds and defaults)
BOUNDED_SEQUENCES = """\
bool[<=3] bool_values
byte[<=3] byte_values
char[<=3] char_values
float32[<=3] float32_values
int64[<=3] int64_values
string[<=3] string_values
string<=5[<=3] bounded_string_values
std_msgs/Empty[<=3] empty_values
bool[<=3] bool_values_default [false, true, false]
int32[<=3] int32_values_default [0, 2147483647, -2147483648]
string[<=3] string_values_default ['', 'max value', 'min value']
int32 alignment_check
"""
DEFAULTS = """\
bool bool_value true
byte byte_value 50
char char_value 100
float32 float32_value 1.125
float64 float64_value 1.125
int8 int8_value -50
uint8 uint8_value 200
int16 int16_value -1000
uint16 uint16_value 2000
int32 int32_value -30000
uint32 uint32_value 60000
int64 int64_value -40000000
uint64 uint64_value 50000000
"""


@pytest.fixture
def test_msgs(make_package, processes: Processes) -> None:
    """/bounded_sequences and /defaults published with default values, as ros2cli's fixtures."""
    make_package(
        "cli_test_msgs",
        {"msg/BoundedSequences.msg": BOUNDED_SEQUENCES, "msg/Defaults.msg": DEFAULTS},
    )
    for topic, name in (("/bounded_sequences", "BoundedSequences"), ("/defaults", "Defaults")):
        child = Watched(processes.python(PUBLISHER_OF, name.lower(), topic, "cli_test_msgs.msg",
                                         name))  # fmt: skip
        child.wait_ready()
    wait_graph(lambda g: g.count(PUBLISHER, "/defaults") == 1)


def test_echo_no_arr_of_bounded_sequences_prints_ros2s_placeholders(test_msgs, processes) -> None:
    result = run(processes, "topic", "echo", "--no-arr", "--once", "/bounded_sequences")
    assert result == Result(
        0,
        "bool_values: '<sequence type: boolean[3], length: 0>'\n"
        "byte_values: '<sequence type: octet[3], length: 0>'\n"
        "char_values: '<sequence type: uint8[3], length: 0>'\n"
        "float32_values: '<sequence type: float[3], length: 0>'\n"
        "int64_values: '<sequence type: int64[3], length: 0>'\n"
        "string_values: '<sequence type: string[3], length: 0>'\n"
        "bounded_string_values: '<sequence type: string[3], length: 0>'\n"
        "empty_values: '<sequence type: std_msgs/msg/Empty[3], length: 0>'\n"
        "bool_values_default: '<sequence type: boolean[3], length: 3>'\n"
        "int32_values_default: '<sequence type: int32[3], length: 3>'\n"
        "string_values_default: '<sequence type: string[3], length: 3>'\n"
        "alignment_check: 0\n"
        "---\n",
        "",
    )


def test_echo_csv_prints_a_byte_field_as_python_bytes_as_ros2(test_msgs, processes) -> None:
    result = run(processes, "topic", "echo", "--csv", "--once", "/defaults")
    assert result == Result(
        0, "True,b'2',100,1.125,1.125,-50,200,-1000,2000,-30000,60000,-40000000,50000000\n", ""
    )
    # a byte field alone prints as Python prints it
    field = run(processes, "topic", "echo", "--once", "--field", "byte_value", "/defaults")
    assert field == Result(0, "b'2'\n---\n", "")


def test_echo_field_that_is_no_member_is_ros2s_line(system, processes) -> None:
    result, took = timed(processes, "topic", "echo", "/my_data", "--field", "not_member")
    assert result.out == ""
    assert assert_user_error(result) == (
        "Invalid field 'not_member': 'MyData' object has no attribute 'not_member'"
    )
    assert took < 20.0  # known from the type: refused, not waiting on
    deeper = run(processes, "topic", "echo", "/my_data", "--field", "label.x", "--once")
    assert assert_user_error(deeper) == "Invalid field 'label.x': 'str' object has no attribute 'x'"
    assert assert_user_error(run(processes, "topic", "echo", "/my_data", "--field", ".")) == (
        "Invalid field value '.'"
    )


def test_type_of_a_hidden_topic_exits_1_unless_hidden_topics_are_included(processes) -> None:
    Watched(processes.python(PUBLISHER_OF, "hider", "/_hidden_chatter", "std_msgs.msg", "String"))
    wait_graph(lambda g: g.count(PUBLISHER, "/_hidden_chatter") == 1)
    assert run(processes, "topic", "type", "/_hidden_chatter") == Result(1, "", "")
    shown = Result(0, "std_msgs/msg/String\n", "")
    assert run(processes, "topic", "type", "/_hidden_chatter", "--include-hidden-topics") == shown
    # ros2 takes the flag before the verb too
    assert run(processes, "topic", "--include-hidden-topics", "type", "/_hidden_chatter") == shown
    listed = run(processes, "topic", "--include-hidden-topics", "list")
    assert "/_hidden_chatter\n" in listed.out
    assert "/_hidden_chatter" not in run(processes, "topic", "list").out


def test_find_of_a_name_that_is_no_type_prints_nothing_and_exits_0(system, processes) -> None:
    assert run(processes, "topic", "find", "not_a_type") == Result(0, "", "")
    assert run(processes, "topic", "find", "rcl_interfaces/msg/NotAMessageTypeName") == Result(
        0, "", ""
    )


def _qos_of(processes: Processes, topic: str, kind: str) -> list[str]:
    """The QoS lines of the one ``kind`` (PUBLISHER/SUBSCRIPTION) endpoint ``topic info -v``."""
    lines = run(processes, "topic", "info", "-v", topic).out.splitlines()
    start = lines.index(f"Endpoint type: {kind}")
    return lines[start + 3 : start + 6]


def test_pub_qos_options_set_the_publishers_policies(processes) -> None:
    pub = Watched(processes.rosl("topic", "pub", "-r", "5", "--qos-reliability", "best_effort",
                                 "--qos-durability", "transient_local", "--qos-depth", "3",
                                 "/qos_a", "std_msgs/msg/String"))  # fmt: skip
    wait_graph(lambda g: g.count(PUBLISHER, "/qos_a") == 1)
    assert _qos_of(processes, "/qos_a", "PUBLISHER") == [
        "  Reliability: BEST_EFFORT",
        "  History (Depth): KEEP_LAST (3)",
        "  Durability: TRANSIENT_LOCAL",
    ]
    pub.interrupt()
    Watched(processes.rosl("topic", "pub", "-r", "5", "--qos-profile", "sensor_data", "/qos_b",
                           "std_msgs/msg/String"))  # fmt: skip
    wait_graph(lambda g: g.count(PUBLISHER, "/qos_b") == 1)
    assert _qos_of(processes, "/qos_b", "PUBLISHER") == [
        "  Reliability: BEST_EFFORT",
        "  History (Depth): KEEP_LAST (5)",
        "  Durability: VOLATILE",
    ]
    wrong = run(processes, "topic", "pub", "--qos-profile", "fast", "/x", "std_msgs/msg/String")
    assert wrong.code == 2
    assert "'fast' is not one of 'system_default', 'sensor_data'" in wrong.err


def test_echo_matches_reliable_publishers_or_takes_the_qos_options(system, processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/my_data"))
    assert echo.wait_for("^counter: 7$", timeout=30)
    # every publisher of /my_data is reliable: echo asks for reliable, as ros2's does
    assert _qos_of(processes, "/my_data", "SUBSCRIPTION")[0] == "  Reliability: RELIABLE"
    echo.interrupt()
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/my_data") == 0)
    given = Watched(processes.rosl("topic", "echo", "/my_data", "--qos-reliability", "best_effort",
                                   "--qos-depth", "7"))  # fmt: skip
    assert given.wait_for("^counter: 7$", timeout=30)
    assert _qos_of(processes, "/my_data", "SUBSCRIPTION") == [
        "  Reliability: BEST_EFFORT",
        "  History (Depth): KEEP_LAST (7)",
        "  Durability: VOLATILE",
    ]


# argv: topic; publishes std_msgs/Int32 counting up at 20 Hz until "stop" on stdin
COUNTER = """
import sys
import threading
import rosl
from std_msgs.msg import Int32

topic = sys.argv[1]
rosl.init([])
node = rosl.Node("counter")
pub = node.create_publisher(Int32, topic, 10)
state = {"n": 0, "on": True}


def tick():
    if state["on"]:
        state["n"] += 1
        pub.publish(Int32(data=state["n"]))


def stop():
    if sys.stdin.readline().strip() != "stop":
        return
    state["on"] = False
    print("stopped", flush=True)


threading.Thread(target=stop, daemon=True).start()
node.create_timer(0.05, tick)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def _bytes_per_second(line: str) -> float:
    found = re.fullmatch(r"(\d+(?:\.\d+)?) (B|KB|MB)/s from \d+ messages", line)
    assert found, line
    return float(found.group(1)) * {"B": 1, "KB": 1e3, "MB": 1e6}[found.group(2)]


def test_bw_divides_by_the_time_since_the_first_message_as_ros2(processes) -> None:
    import subprocess

    bw = Watched(processes.rosl("topic", "bw", "/count"))
    counter = Watched(processes.python(COUNTER, "/count", stdin=subprocess.PIPE))
    counter.wait_ready()
    assert bw.wait_for(r"B/s from", timeout=30), bw.text("err")
    counter.tell("stop")
    assert counter.wait_for("^stopped$", timeout=30)
    seen = len(bw.matching(r"B/s from"))
    assert bw.wait_for(r"B/s from", timeout=30, count=seen + 3), bw.text("err")
    bw.interrupt()
    reports = [line for line in bw.lines() if "B/s from" in line]
    # nothing arrives any more: the same bytes over a longer time, so it falls (ros2's formula)
    before, after = reports[-2], reports[-1]
    assert before.split(" from ")[1] == after.split(" from ")[1]
    assert _bytes_per_second(after) < _bytes_per_second(before), reports


def test_hz_filter_neither_counts_nor_loses_the_filtered_messages(processes) -> None:
    Watched(processes.python(COUNTER, "/count")).wait_ready()
    hz = Watched(processes.rosl("topic", "hz", "/count", "--filter", "m.data % 2 == 0"))
    assert hz.wait_for(r"window: \d+$", timeout=30, count=3), hz.text("err")
    hz.interrupt()
    assert not [line for line in hz.lines() if "lost" in line], hz.lines()
    assert "Traceback" not in hz.text("err")


def test_hz_of_a_misspelt_topic_names_the_close_one_and_keeps_waiting(system, processes) -> None:
    hz = Watched(processes.rosl("topic", "hz", "/my_dat"))
    assert hz.wait_for(r"did you mean", "err", timeout=30), hz.text("err")
    assert hz.lines("err") == ["no topic /my_dat yet (did you mean '/my_data'?); waiting for it"]
    assert hz.wait_for("WARNING", timeout=30)
    assert hz.lines() == ["WARNING: topic [/my_dat] does not appear to be published yet"]
    assert hz.child.poll() is None  # still waiting, as ros2's hz does
    hz.interrupt()


def test_pub_and_echo_of_a_byte_array_use_rclpys_bytes_and_ros2s_yaml(processes) -> None:
    # rclpy holds byte as bytes of length 1; ros2 topic echo shows each as its character
    echo = Watched(processes.rosl("topic", "echo", "/bytes", "std_msgs/msg/ByteMultiArray",
                                  "--once", env={"NO_COLOR": "1"}))  # fmt: skip
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/bytes") == 1)

    pub = run(processes, "topic", "pub", "--once", "-w", "1", "/bytes",
              "std_msgs/msg/ByteMultiArray", "{data: [0, 1, 255]}")  # fmt: skip

    assert pub.code == 0, pub
    assert "data=[b'\\x00', b'\\x01', b'\\xff'])" in pub.out
    assert echo.wait_for("^---$", timeout=30.0), echo.text("err")
    assert echo.lines() == [
        "layout:", "  dim: []", "  data_offset: 0", "data:", '- "\\0"', '- "\\x01"', "- ÿ", "---"
    ]  # fmt: skip
    assert echo.child.wait(timeout=30) == 0, echo.text("err")  # --once: it ends by itself


def test_echo_field_of_a_byte_array_prints_the_characters_not_base64(processes) -> None:
    echo = Watched(processes.rosl("topic", "echo", "/field_bytes", "std_msgs/msg/ByteMultiArray",
                                  "--once", "--field", "data", env={"NO_COLOR": "1"}))  # fmt: skip
    wait_graph(lambda g: g.count(SUBSCRIPTION, "/field_bytes") == 1)
    pub = run(processes, "topic", "pub", "--once", "-w", "1", "/field_bytes",
              "std_msgs/msg/ByteMultiArray", "{data: [65, 66]}")  # fmt: skip
    assert pub.code == 0, pub
    assert echo.wait_for("^---$", timeout=30.0), echo.text("err")
    assert echo.lines() == ["- A", "- B", "---"]  # as in the message's YAML, never !!binary
    echo.interrupt()


def test_echo_says_when_only_some_publishers_are_reliable_as_ros2(system, processes) -> None:
    Watched(processes.rosl("topic", "pub", "-r", "5", "--qos-reliability", "best_effort",
                           "/my_data", "tutorial_pkg/msg/MyData"))  # fmt: skip
    wait_graph(lambda g: g.count(PUBLISHER, "/my_data") == 2)
    echo = Watched(processes.rosl("topic", "echo", "/my_data"))
    assert echo.wait_for("^---$", timeout=30), echo.text("err")
    echo.interrupt()
    assert echo.lines()[0] == (
        "Some, but not all, publishers are offering QoSReliabilityPolicy.RELIABLE. Falling back "
        "to QoSReliabilityPolicy.BEST_EFFORT as it will connect to all publishers"
    )


def test_echo_raw_prints_the_serialized_bytes_then_dashes(processes) -> None:
    Watched(processes.rosl("topic", "pub", "-r", "5", "/raw", "std_msgs/msg/String",
                           "{data: hello}"))  # fmt: skip
    wait_graph(lambda g: g.count(PUBLISHER, "/raw") == 1)
    result = run(processes, "topic", "echo", "--raw", "--once", "/raw")
    assert result.code == 0, result.err
    # the CDR header, the length 6, 'hello' and its NUL, as ros2 prints them
    assert result.out.startswith("b'\\x00\\x01\\x00\\x00\\x06\\x00\\x00\\x00hello\\x00")
    assert result.out.endswith("'\n---\n")
