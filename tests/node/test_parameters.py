"""Parameters: declaration, overrides from the command line and files, typed updates,
callbacks, descriptors, atomic sets, the rcl_interfaces services and /parameter_events."""

from __future__ import annotations

import pytest

from tests.node.helpers import spin_until

WRONG_TYPE = (  # an override at declaration (rcl's words)
    "Wrong parameter type, parameter {{{name}}} is of type {{{declared}}}, "
    "setting it to {{{given}}} is not allowed."
)
WRONG_TYPE_SET = "Wrong parameter type, expected 'Type.{declared}' got 'Type.{given}'"  # rclpy's


def test_a_declared_parameter_has_its_default_when_nothing_overrides_it(ros):
    node = ros.Node("defaults")
    param = node.declare_parameter("rate", 2.5)
    assert param.value == 2.5
    assert node.get_parameter("rate").value == 2.5
    assert node.get_parameter("rate").as_double() == 2.5
    assert node.get_parameter("rate").type_ is ros.Parameter.Type.DOUBLE
    assert node.has_parameter("rate")
    assert not node.has_parameter("other")


def test_ros_args_p_overrides_are_read_as_yaml_typed_values(ros):
    node = ros.Node(
        "typed",
        cli_args=[
            "--ros-args",
            "-p", "ratio:=1.5",
            "-p", "count:=3",
            "-p", "enabled:=true",
            "-p", "ids:=[1,2]",
            "-p", "greeting:=hello world",
            "-p", "rate:=3",
            "-p", "other_node:count:=99",
        ],
    )  # fmt: skip
    ratio = node.declare_parameter("ratio", 0.0)
    count = node.declare_parameter("count", 0)
    enabled = node.declare_parameter("enabled", False)
    ids = node.declare_parameter("ids", [0])
    greeting = node.declare_parameter("greeting", "hi")
    rate = node.declare_parameter("rate", 1.0)

    assert (ratio.value, ratio.type_) == (1.5, ros.Parameter.Type.DOUBLE)
    assert (count.value, count.type_) == (3, ros.Parameter.Type.INTEGER)
    assert (enabled.value, enabled.type_) == (True, ros.Parameter.Type.BOOL)
    assert (ids.value, ids.type_) == ([1, 2], ros.Parameter.Type.INTEGER_ARRAY)
    assert (greeting.value, greeting.type_) == ("hello world", ros.Parameter.Type.STRING)
    # an int given for a double parameter becomes a double
    assert rate.type_ is ros.Parameter.Type.DOUBLE
    assert isinstance(rate.value, float)
    assert rate.value == 3.0
    assert node.get_parameter("rate").as_double() == 3.0


def test_global_ros_args_reach_nodes_of_the_process(spawn):
    child = spawn(
        """
        import rosl
        rosl.init()
        node = rosl.Node("cli_node")
        print("gain", repr(node.declare_parameter("gain", 0.5).value), flush=True)
        print("name", repr(node.declare_parameter("label", "x").value), flush=True)
        rosl.shutdown()
        """,
        "--ros-args", "-p", "gain:=4", "-p", "label:=front camera",
    )  # fmt: skip
    child.expect("^gain 4.0$")
    child.expect("^name 'front camera'$")


def test_a_params_file_applies_wildcards_then_the_node_section(ros, tmp_path):
    params = tmp_path / "params.yaml"
    params.write_text(
        "file_node:\n"
        "  ros__parameters:\n"
        "    who: specific\n"
        "    nested:\n"
        "      gain: 2\n"
        "/**:\n"
        "  ros__parameters:\n"
        "    who: wildcard\n"
        "    shared: 7\n"
        "    speed: 1\n"
        "someone_else:\n"
        "  ros__parameters:\n"
        "    shared: 1000\n"
    )
    node = ros.Node("file_node", cli_args=["--ros-args", "--params-file", str(params)])

    assert node.declare_parameter("who", "default").value == "specific"
    assert node.declare_parameter("shared", 0).value == 7
    assert node.declare_parameter("nested.gain", 0).value == 2
    speed = node.declare_parameter("speed", 0.5)
    assert speed.type_ is ros.Parameter.Type.DOUBLE
    assert speed.value == 1.0


def test_command_line_p_wins_over_a_params_file(ros, tmp_path):
    params = tmp_path / "params.yaml"
    params.write_text("/**:\n  ros__parameters:\n    level: 1\n")
    node = ros.Node("both", cli_args=["--ros-args", "--params-file", str(params), "-p", "level:=2"])
    assert node.declare_parameter("level", 0).value == 2


def test_a_malformed_params_file_is_a_clear_error(ros, tmp_path):
    from rosl.node.errors import RosArgsError

    params = tmp_path / "bad.yaml"
    params.write_text("file_node:\n  speed: 1\n")
    with pytest.raises(RosArgsError, match="ros__parameters"):
        ros.Node("file_node", cli_args=["--ros-args", "--params-file", str(params)])


def test_setting_a_parameter_to_another_type_is_refused_with_ros2s_text(ros):
    node = ros.Node("strict")
    node.declare_parameter("speed", 1.5)

    [result] = node.set_parameters([ros.Parameter("speed", value="fast")])

    assert not result.successful
    assert result.reason == WRONG_TYPE_SET.format(declared="DOUBLE", given="STRING")
    assert node.get_parameter("speed").value == 1.5
    # an int for a double is refused too, as rclpy refuses it (an override at start is not)
    [refused] = node.set_parameters([ros.Parameter("speed", value=4)])
    assert refused.reason == WRONG_TYPE_SET.format(declared="DOUBLE", given="INTEGER")
    assert node.get_parameter("speed").value == 1.5
    assert node.get_parameter("speed").type_ is ros.Parameter.Type.DOUBLE


def test_reading_a_parameter_as_the_wrong_type_or_undeclared_raises(ros):
    from rosl.node.errors import InvalidParameterTypeException, ParameterNotDeclaredException

    node = ros.Node("reader")
    node.declare_parameter("name", "bob")
    with pytest.raises(InvalidParameterTypeException, match="string"):
        node.get_parameter("name").as_double()
    with pytest.raises(ParameterNotDeclaredException, match="missing"):
        node.get_parameter("missing")
    [result] = node.set_parameters([ros.Parameter("missing", value=1)])
    assert not result.successful
    assert "missing" in result.reason


def test_an_on_set_callback_can_refuse_a_change_with_a_reason(ros):
    from rcl_interfaces.msg import SetParametersResult

    node = ros.Node("guarded")
    node.declare_parameter("speed", 1.0)
    seen: list[list[str]] = []

    def check(params):
        seen.append([p.name for p in params])
        for p in params:
            if p.name == "speed" and p.value > 10.0:
                return SetParametersResult(successful=False, reason="speed must be <= 10")
        return SetParametersResult(successful=True)

    node.add_on_set_parameters_callback(check)
    [refused] = node.set_parameters([ros.Parameter("speed", value=20.0)])
    [accepted] = node.set_parameters([ros.Parameter("speed", value=5.0)])

    assert (refused.successful, refused.reason) == (False, "speed must be <= 10")
    assert accepted.successful
    assert node.get_parameter("speed").value == 5.0
    assert seen == [["speed"], ["speed"]]
    node.remove_on_set_parameters_callback(check)
    assert node.set_parameters([ros.Parameter("speed", value=20.0)])[0].successful


def test_an_on_set_callback_that_raises_fails_the_change_and_the_node_goes_on(ros, capfd):
    node = ros.Node("buggy")
    node.declare_parameter("period", 1.0)
    periods_ns: list[int] = []

    def on_set(params):
        for p in params:
            periods_ns.append(int(p.value * 1e9))  # nan: ValueError, as in the tutorial's node
        return None

    node.add_on_set_parameters_callback(on_set)
    [failed] = node.set_parameters([ros.Parameter("period", value=float("nan"))])
    [changed] = node.set_parameters([ros.Parameter("period", value=2.0)])

    assert (failed.successful, failed.reason) == (
        False,
        "ValueError: cannot convert float NaN to integer",
    )
    assert changed.successful
    assert node.get_parameter("period").value == 2.0
    assert periods_ns == [2_000_000_000]
    err = capfd.readouterr().err
    assert (
        "[buggy]: exception in callback for on_set_parameters: ValueError: cannot convert " in err
    )


def test_a_byte_array_parameter_goes_through_its_message_as_rclpys_list_of_bytes(ros):
    from rosl.node.parameters import value_from_msg

    param = ros.Parameter("raw", value=[b"\x01", b"\xff"])  # rclpy's spelling of a byte array
    msg = param.get_parameter_value()

    assert param.type_ is ros.Parameter.Type.BYTE_ARRAY
    assert msg.byte_array_value == [b"\x01", b"\xff"]
    assert value_from_msg(msg) == (ros.Parameter.Type.BYTE_ARRAY, b"\x01\xff")


def test_a_read_only_parameter_cannot_be_set(ros):
    from rcl_interfaces.msg import ParameterDescriptor

    node = ros.Node("constant")
    node.declare_parameter("serial", "A123", ParameterDescriptor(read_only=True))

    [result] = node.set_parameters([ros.Parameter("serial", value="B456")])

    assert not result.successful
    assert "read-only" in result.reason
    assert "serial" in result.reason
    assert node.get_parameter("serial").value == "A123"
    assert node.describe_parameter("serial").read_only is True


def test_a_parameter_outside_its_descriptor_range_is_refused(ros):
    from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor

    node = ros.Node("ranged")
    descriptor = ParameterDescriptor(
        floating_point_range=[FloatingPointRange(from_value=0.0, to_value=1.0, step=0.0)]
    )
    node.declare_parameter("alpha", 0.5, descriptor)
    [result] = node.set_parameters([ros.Parameter("alpha", value=1.5)])
    assert not result.successful
    assert "alpha" in result.reason
    assert node.get_parameter("alpha").value == 0.5


def test_set_parameters_atomically_changes_all_or_nothing(ros):
    node = ros.Node("atomic")
    node.declare_parameter("a", 1)
    node.declare_parameter("b", 2.0)

    refused = node.set_parameters_atomically(
        [ros.Parameter("a", value=10), ros.Parameter("b", value="not a double")]
    )
    assert not refused.successful
    assert refused.reason == WRONG_TYPE_SET.format(declared="DOUBLE", given="STRING")
    assert node.get_parameter("a").value == 1
    assert node.get_parameter("b").value == 2.0

    accepted = node.set_parameters_atomically(
        [ros.Parameter("a", value=10), ros.Parameter("b", value=20.0)]
    )
    assert accepted.successful
    assert (node.get_parameter("a").value, node.get_parameter("b").value) == (10, 20.0)


def test_declaring_twice_is_an_error(ros):
    from rosl.node.errors import ParameterAlreadyDeclaredException

    node = ros.Node("twice")
    node.declare_parameter("x", 1)
    with pytest.raises(ParameterAlreadyDeclaredException, match="'x'"):
        node.declare_parameter("x", 2)


REMOTE = """
import rosl
from rcl_interfaces.msg import ParameterDescriptor

rosl.init()
node = rosl.Node("remote_params")
node.declare_parameter("gain", 1.5, ParameterDescriptor(description="how strong"))
node.declare_parameter("mode", "auto")
node.declare_parameter("limits.low", 1)
node.declare_parameter("limits.high", 9)
node.declare_parameter("fixed", 3, ParameterDescriptor(read_only=True))
last = {}

def report():
    value = node.get_parameter("gain").value
    if last.get("gain") != value:
        last["gain"] = value
        print("gain is", value, flush=True)

node.create_timer(0.05, report)
print("ready", flush=True)
rosl.spin(node)
"""


def _value(msg):
    from rosl.node.parameters import value_from_msg

    return value_from_msg(msg)[1]


def test_another_process_reads_and_changes_parameters_through_the_services(ros, spawn):
    from rcl_interfaces.msg import Parameter as ParameterMsg
    from rcl_interfaces.msg import ParameterType, ParameterValue
    from rcl_interfaces.srv import (
        DescribeParameters,
        GetParameters,
        GetParameterTypes,
        ListParameters,
        SetParameters,
    )

    child = spawn(REMOTE)
    child.expect("^ready$")
    child.expect("^gain is 1.5$")
    node = ros.Node("param_tool")

    def client(srv, name):
        c = node.create_client(srv, f"/remote_params/{name}")
        assert c.wait_for_service(timeout_sec=20.0), name
        return c

    got = client(GetParameters, "get_parameters").call(
        GetParameters.Request(names=["gain", "mode", "nope"]), timeout_sec=15.0
    )
    assert [_value(v) for v in got.values] == [1.5, "auto", None]

    types = client(GetParameterTypes, "get_parameter_types").call(
        GetParameterTypes.Request(names=["gain", "mode", "limits.low"]), timeout_sec=15.0
    )
    assert list(types.types) == [
        ParameterType.PARAMETER_DOUBLE,
        ParameterType.PARAMETER_STRING,
        ParameterType.PARAMETER_INTEGER,
    ]

    listed = client(ListParameters, "list_parameters").call(
        ListParameters.Request(), timeout_sec=15.0
    )
    assert {"gain", "mode", "limits.low", "limits.high", "fixed", "use_sim_time"} <= set(
        listed.result.names
    )
    assert "limits" in listed.result.prefixes
    only_limits = client(ListParameters, "list_parameters").call(
        ListParameters.Request(prefixes=["limits"]), timeout_sec=15.0
    )
    assert sorted(only_limits.result.names) == ["limits.high", "limits.low"]

    described = client(DescribeParameters, "describe_parameters").call(
        DescribeParameters.Request(names=["gain", "fixed"]), timeout_sec=15.0
    )
    assert [(d.name, d.type, d.description, d.read_only) for d in described.descriptors] == [
        ("gain", ParameterType.PARAMETER_DOUBLE, "how strong", False),
        ("fixed", ParameterType.PARAMETER_INTEGER, "", True),
    ]

    setter = client(SetParameters, "set_parameters")
    request = SetParameters.Request(
        parameters=[
            ParameterMsg(
                name="gain",
                value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=2.5),
            ),
            ParameterMsg(
                name="mode",
                value=ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=3),
            ),
            ParameterMsg(
                name="fixed",
                value=ParameterValue(type=ParameterType.PARAMETER_INTEGER, integer_value=4),
            ),
        ]
    )
    results = setter.call(request, timeout_sec=15.0).results
    assert [r.successful for r in results] == [True, False, False]
    assert results[1].reason == WRONG_TYPE_SET.format(declared="STRING", given="INTEGER")
    assert "read-only" in results[2].reason
    child.expect("^gain is 2.5$")
    again = client(GetParameters, "get_parameters").call(
        GetParameters.Request(names=["gain", "mode", "fixed"]), timeout_sec=15.0
    )
    assert [_value(v) for v in again.values] == [2.5, "auto", 3]


def test_parameter_changes_are_published_on_parameter_events(ros, spawn):
    from rcl_interfaces.msg import ParameterEvent
    from rcl_interfaces.srv import SetParameters

    child = spawn(REMOTE)
    child.expect("^ready$")
    node = ros.Node("event_watcher")
    events: list[ParameterEvent] = []
    node.create_subscription(ParameterEvent, "/parameter_events", events.append, 10)
    setter = node.create_client(SetParameters, "/remote_params/set_parameters")
    assert setter.wait_for_service(timeout_sec=20.0)

    request = SetParameters.Request(
        parameters=[ros.Parameter("gain", value=7.25).to_parameter_msg()]
    )
    assert setter.call(request, timeout_sec=15.0).results[0].successful

    def changed_gain():
        return [
            e
            for e in events
            if e.node == "/remote_params" and any(p.name == "gain" for p in e.changed_parameters)
        ]

    assert spin_until(node, lambda: bool(changed_gain()), 15.0), [e.node for e in events]
    event = changed_gain()[0]
    [param] = [p for p in event.changed_parameters if p.name == "gain"]
    assert _value(param.value) == 7.25
    assert list(event.new_parameters) == []
    assert list(event.deleted_parameters) == []


def test_the_nodes_own_declarations_and_sets_are_published_on_parameter_events(ros):
    from rcl_interfaces.msg import ParameterEvent

    watcher = ros.Node("own_watcher")
    events: list[ParameterEvent] = []
    watcher.create_subscription(ParameterEvent, "/parameter_events", events.append, 10)
    node = ros.Node("own_events", namespace="/lab")
    spin_until(watcher, lambda: False, 0.2)  # let the subscription settle

    node.declare_parameter("threshold", 0.25)
    node.set_parameters([ros.Parameter("threshold", value=0.75)])

    def mine():
        return [e for e in events if e.node == "/lab/own_events"]

    assert spin_until(
        watcher,
        lambda: any(p.name == "threshold" for e in mine() for p in e.changed_parameters),
        5.0,
    )
    new = [p for e in mine() for p in e.new_parameters if p.name == "threshold"]
    changed = [p for e in mine() for p in e.changed_parameters if p.name == "threshold"]
    assert [_value(p.value) for p in new] == [0.25]
    assert [_value(p.value) for p in changed] == [0.75]


def test_an_override_of_the_wrong_type_makes_the_declaration_fail(ros):
    from rosl.node.errors import InvalidParameterTypeException

    node = ros.Node("overridden", cli_args=["--ros-args", "-p", "rate:=fast"])
    with pytest.raises(InvalidParameterTypeException) as err:
        node.declare_parameter("rate", 1.0)
    assert str(err.value) == WRONG_TYPE.format(name="rate", declared="double", given="string")


def test_an_integer_range_with_a_step_refuses_values_off_the_step(ros):
    from rcl_interfaces.msg import IntegerRange, ParameterDescriptor

    node = ros.Node("stepped")
    descriptor = ParameterDescriptor(
        integer_range=[IntegerRange(from_value=0, to_value=10, step=2)]
    )
    node.declare_parameter("k", 4, descriptor)
    results = node.set_parameters(
        [ros.Parameter("k", value=5), ros.Parameter("k", value=6), ros.Parameter("k", value=12)]
    )
    assert [r.successful for r in results] == [False, True, False]
    assert node.get_parameter("k").value == 6


def test_parameters_declared_under_a_namespace_are_found_by_prefix(ros):
    node = ros.Node("prefixed")
    node.declare_parameters("cam", [("fps", 30), ("name", "front")])
    found = node.get_parameters_by_prefix("cam")
    assert {k: p.value for k, p in found.items()} == {"fps": 30, "name": "front"}
    node.undeclare_parameter("cam.fps")
    assert not node.has_parameter("cam.fps")
    assert [p.value for p in node.get_parameters(["cam.name"])] == ["front"]


def test_overrides_can_be_declared_automatically_and_undeclared_ones_allowed(ros):
    node = ros.Node(
        "auto",
        cli_args=["--ros-args", "-p", "speed:=2.5", "-p", "label:=left"],
        automatically_declare_parameters_from_overrides=True,
    )
    assert node.get_parameter("speed").value == 2.5
    assert node.get_parameter("label").value == "left"

    loose = ros.Node("loose", allow_undeclared_parameters=True)
    assert loose.get_parameter("anything").type_ is ros.Parameter.Type.NOT_SET
    assert loose.set_parameters([ros.Parameter("anything", value=3)])[0].successful
    assert loose.get_parameter("anything").value == 3


def test_a_namespaced_nodes_parameter_services_live_under_its_full_name(ros):
    from rcl_interfaces.srv import GetParameters

    node = ros.Node("cam", namespace="/robot")
    node.declare_parameter("fps", 30)
    other = ros.Node("asker")
    client = other.create_client(GetParameters, "/robot/cam/get_parameters")
    assert client.wait_for_service(timeout_sec=20.0)
    future = client.call_async(GetParameters.Request(names=["fps"]))
    executor = ros.SingleThreadedExecutor()  # runs both nodes: an executor runs only its own
    executor.add_node(node)
    executor.add_node(other)
    executor.spin_until_future_complete(future, timeout_sec=15.0)
    assert future.done()
    assert future.result().values[0].integer_value == 30
    # the graph hears the node's services as its announcements arrive (a loaded machine may
    # have told only some of them yet, as with ROS 2's discovery)
    wanted = ("/robot/cam/set_parameters", ["rcl_interfaces/srv/SetParameters"])
    assert spin_until(other, lambda: wanted in other.get_service_names_and_types(), 20.0), (
        other.get_service_names_and_types()
    )


def test_a_pre_set_callback_can_add_a_parameter_and_post_set_callbacks_hear_what_was_set(ros):
    node = ros.Node("chained")
    node.declare_parameter("speed", 0.0)
    node.declare_parameter("limit", 0.0)
    heard: list[tuple[str, float]] = []

    def pre(params):  # setting speed also sets limit to twice it
        extra = [ros.Parameter("limit", value=p.value * 2) for p in params if p.name == "speed"]
        return list(params) + extra

    def post(params):
        heard.extend((p.name, p.value) for p in params)

    node.add_pre_set_parameters_callback(pre)
    node.add_post_set_parameters_callback(post)
    results = node.set_parameters([ros.Parameter("speed", value=1.5)])

    assert [r.successful for r in results] == [True, True]
    assert node.get_parameter("limit").value == 3.0
    assert heard == [("speed", 1.5), ("limit", 3.0)]
    node.remove_pre_set_parameters_callback(pre)
    node.remove_post_set_parameters_callback(post)
    assert len(node.set_parameters([ros.Parameter("speed", value=1.0)])) == 1
    assert node.get_parameter("limit").value == 3.0
    assert len(heard) == 2


def test_a_pre_set_callback_that_empties_the_list_fails_the_set(ros):
    node = ros.Node("emptied")
    node.declare_parameter("speed", 0.0)
    node.add_pre_set_parameters_callback(lambda params: [])

    [result] = node.set_parameters([ros.Parameter("speed", value=1.5)])

    assert not result.successful
    assert "parameter list cannot be empty" in result.reason
    assert node.get_parameter("speed").value == 0.0


def test_an_async_parameter_client_sets_lists_gets_loads_and_deletes_another_nodes_parameters(
    ros, tmp_path
):
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient

    board = ros.Node("board", allow_undeclared_parameters=True)
    board.declare_parameter("fixed", 1)
    asker = ros.Node("asker")
    executor = ros.SingleThreadedExecutor()
    executor.add_node(board)
    executor.add_node(asker)
    client = AsyncParameterClient(asker, "board")
    assert client.wait_for_services(20.0)

    def done(future):
        executor.spin_until_future_complete(future, timeout_sec=15.0)
        assert future.done()
        return future.result()

    set_result = done(client.set_parameters([ros.Parameter("count", value=10)]))
    listed = done(client.list_parameters(["count", "fixed"], 10))
    got = done(client.get_parameters(["count", "fixed"]))
    types = done(client.get_parameter_types(["count"]))
    path = tmp_path / "params.yaml"
    path.write_text("board:\n  ros__parameters:\n    label: front\n    fixed: 7\n")
    loaded = done(client.load_parameter_file(str(path)))
    deleted = done(client.delete_parameters(["fixed"]))

    assert [r.successful for r in set_result.results] == [True]
    assert sorted(listed.result.names) == ["count", "fixed"]
    assert [parameter_value_to_python(v) for v in got.values] == [10, 1]
    assert list(types.types) == [ros.Parameter.Type.INTEGER.value]
    assert [r.successful for r in loaded.results] == [True, True]
    assert board.get_parameter("label").value == "front"
    assert board.get_parameter("fixed").value == 7
    assert [(r.successful, r.reason) for r in deleted.results] == [
        (False, "Static parameter cannot be undeclared")
    ]


def test_an_async_parameter_client_does_not_find_a_node_that_is_not_there(ros):
    from rclpy.parameter_client import AsyncParameterClient

    client = AsyncParameterClient(ros.Node("asker"), "nobody")

    assert not client.wait_for_services(0.5)
    assert not client.services_are_ready()
