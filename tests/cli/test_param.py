"""``rosl param`` against real nodes in other processes, compared with ROS 2's exact texts."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import assert_user_error, run
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.cli.conftest import Result
    from tests.conftest import Processes

PARAM_NODE = """
import rosl
from rcl_interfaces.msg import (
    FloatingPointRange, IntegerRange, ParameterDescriptor, SetParametersResult,
)

rosl.init([])
node = rosl.Node("param_node")
node.declare_parameter("speed", 2.0)
node.declare_parameter("count", 5, ParameterDescriptor(
    description="how many", integer_range=[IntegerRange(from_value=0, to_value=10, step=1)]))
node.declare_parameter("ratio", 0.5, ParameterDescriptor(
    floating_point_range=[FloatingPointRange(from_value=0.0, to_value=1.0)]))
node.declare_parameter("enabled", True)
node.declare_parameter("label", "hello")
node.declare_parameter("gains", [1.0, 2.5])
node.declare_parameter("ids", [1, 2, 3])
node.declare_parameter("names", ["a", "b"])
node.declare_parameter("flags", [True, False])
node.declare_parameter("limits.max", 9.5)
node.declare_parameter("limits.min", -1.5)
node.declare_parameter("frame", "base", ParameterDescriptor(
    read_only=True, additional_constraints="fixed at start"))
node.declare_parameter("anything", 1, ParameterDescriptor(dynamic_typing=True))
node.declare_parameter("shared", 0)


def refuse_forbidden(params):
    for param in params:
        if param.name == "label" and param.value == "forbidden":
            return SetParametersResult(successful=False, reason="label may not be 'forbidden'")
    return SetParametersResult(successful=True)


node.add_on_set_parameters_callback(refuse_forbidden)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

AUX_NODE = """
import rosl

rosl.init([])
node = rosl.Node("zeta", namespace="/a")
node.declare_parameter("level", 3)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

NAMES = ["anything", "count", "enabled", "flags", "frame", "gains", "ids", "label", "limits.max",
         "limits.min", "names", "ratio", "shared", "speed", "use_sim_time"]  # fmt: skip

DUMP = """\
/param_node:
  ros__parameters:
    anything: 1
    count: 5
    enabled: true
    flags:
    - true
    - false
    frame: base
    gains:
    - 1.0
    - 2.5
    ids:
    - 1
    - 2
    - 3
    label: hello
    limits:
      max: 9.5
      min: -1.5
    names:
    - a
    - b
    ratio: 0.5
    shared: 0
    speed: 2.0
    use_sim_time: false
"""


@pytest.fixture
def param_node(processes: Processes) -> Watched:
    child = Watched(processes.python(PARAM_NODE))
    child.wait_ready()
    return child


@pytest.fixture
def param(processes: Processes) -> Callable[..., Result]:
    """``rosl param ARGS`` as a real process."""
    return lambda *args: run(processes, "param", *args)


def get(param: Callable[..., Result], name: str) -> str:
    result = param("get", "/param_node", name)
    assert result.code == 0, result
    return result.out


# --- list -------------------------------------------------------------------------------------


def test_param_list_of_a_named_node_prints_its_names_sorted_with_no_header(
    param_node, param
) -> None:
    result = param("list", "/param_node")
    assert (result.code, result.err) == (0, "")
    assert result.out == "".join(f"  {name}\n" for name in NAMES)
    assert param("list", "param_node").out == result.out  # the leading '/' is optional


def test_param_list_of_every_node_prints_a_header_per_node_sorted_by_name_as_ros2_does(
    param_node, param, processes
) -> None:
    Watched(processes.python(AUX_NODE)).wait_ready()
    result = param("list")
    assert (result.code, result.err) == (0, "")
    # ros2 sorts by (node name, namespace): /param_node before /a/zeta
    expected = ["/param_node:", *(f"  {name}" for name in NAMES), "/a/zeta:", "  level",
                "  use_sim_time"]  # fmt: skip
    assert result.out.splitlines() == expected


def test_param_list_filter_matches_at_the_start_of_names_and_skips_nodes_left_empty(
    param_node, param, processes
) -> None:
    Watched(processes.python(AUX_NODE)).wait_ready()
    assert (
        param("list", "--filter", "l[ai]").out
        == "/param_node:\n  label\n  limits.max\n  limits.min\n"
    )
    assert param("list", "/param_node", "--filter", "l[ai]").out == (
        "  label\n  limits.max\n  limits.min\n"
    )
    assert param("list", "--filter", r".*_sim").out == (
        "/param_node:\n  use_sim_time\n/a/zeta:\n  use_sim_time\n"
    )
    assert_user_error(param("list", "--filter", "("), "--filter", "(")


def test_param_list_param_prefixes_and_param_type(param_node, param) -> None:
    result = param("list", "/param_node", "--param-prefixes", "limits", "speed", "--param-type")
    assert (result.code, result.err) == (0, "")
    assert result.out == (
        "  limits.max (type: double)\n  limits.min (type: double)\n  speed (type: double)\n"
    )
    typed = param("list", "/param_node", "--param-type").out.splitlines()
    assert "  flags (type: boolean array)" in typed
    assert "  names (type: string array)" in typed
    assert "  count (type: integer)" in typed


# --- get --------------------------------------------------------------------------------------


def test_param_get_prints_ros2s_label_and_value_for_every_type(param_node, param) -> None:
    expected = {
        "speed": "Double value is: 2.0",
        "count": "Integer value is: 5",
        "enabled": "Boolean value is: True",
        "label": "String value is: hello",
        # humble prints the message fields as rclpy holds them: array.array for numbers
        "gains": "Double values are: array('d', [1.0, 2.5])",
        "ids": "Integer values are: array('q', [1, 2, 3])",
        "names": "String values are: ['a', 'b']",
        "flags": "Boolean values are: [True, False]",
        "limits.min": "Double value is: -1.5",
    }
    for name, line in expected.items():
        assert get(param, name) == line + "\n"
    hidden = param("get", "/param_node", "speed", "--hide-type")
    assert (hidden.code, hidden.out, hidden.err) == (0, "2.0\n", "")
    assert param("get", "/param_node", "names", "--hide-type").out == "['a', 'b']\n"
    assert param("get", "/param_node", "ids", "--hide-type").out == "array('q', [1, 2, 3])\n"


def test_param_get_of_an_unknown_parameter_or_node_names_the_closest_one(param_node, param) -> None:
    line = assert_user_error(param("get", "/param_node", "sped"))
    assert line == "Parameter not set (did you mean 'speed' or 'shared'?)"
    assert assert_user_error(param("get", "/param_node", "xyzzy")) == "Parameter not set"
    line = assert_user_error(param("get", "/param_nod", "speed"))
    assert line == "Node not found (did you mean '/param_node'?)"
    for verb in (("get", "x"), ("set", "x", "1"), ("delete", "x"), ("describe", "x"), ("dump",)):
        result = param(verb[0], "/invalid_node", *verb[1:])
        assert assert_user_error(result) == "Node not found", verb


# --- set --------------------------------------------------------------------------------------


def test_param_set_prints_set_parameter_successful_and_the_node_takes_the_value(
    param_node, param
) -> None:
    result = param("set", "/param_node", "speed", "0.5")
    assert (result.code, result.out, result.err) == (0, "Set parameter successful\n", "")
    assert get(param, "speed") == "Double value is: 0.5\n"
    negative = param("set", "/param_node", "speed", "-3.5")  # a value, not an option
    assert (negative.code, negative.out, negative.err) == (0, "Set parameter successful\n", "")
    assert get(param, "speed") == "Double value is: -3.5\n"
    assert param("set", "/param_node", "ids", "[4, -5]").out == "Set parameter successful\n"
    assert get(param, "ids") == "Integer values are: array('q', [4, -5])\n"
    assert param("set", "/param_node", "label", "two words").code == 0
    assert get(param, "label") == "String value is: two words\n"


@pytest.mark.parametrize(
    ("name", "value", "reason"),
    [
        ("frame", "other", "Trying to set a read-only parameter: frame."),
        ("count", "11", "Parameter {count} doesn't comply with integer range."),
        ("ratio", "2.0", "Parameter {ratio} doesn't comply with floating point range."),
        ("label", "forbidden", "label may not be 'forbidden'"),
    ],
)
def test_param_set_refused_prints_setting_parameter_failed_with_the_reason_and_exits_1(
    param_node, param, name: str, value: str, reason: str
) -> None:
    before = get(param, name)
    result = param("set", "/param_node", name, value)
    assert (result.code, result.out) == (1, "")
    assert result.err == f"Setting parameter failed: {reason}\n"
    assert get(param, name) == before


def test_param_set_of_the_wrong_type_is_refused(param_node, param) -> None:
    result = param("set", "/param_node", "enabled", "3")
    assert (result.code, result.out) == (1, "")
    assert result.err.startswith("Setting parameter failed: Wrong parameter type")
    assert get(param, "enabled") == "Boolean value is: True\n"
    dynamic = param("set", "/param_node", "anything", "text")  # dynamic typing allows it
    assert (dynamic.code, dynamic.out) == (0, "Set parameter successful\n")
    assert get(param, "anything") == "String value is: text\n"


def test_param_set_of_an_integer_into_a_double_parameter_is_refused_with_rclpys_text(
    param_node, param
) -> None:
    result = param("set", "/param_node", "speed", "1")
    assert result.err == (
        "Setting parameter failed: Wrong parameter type, expected 'Type.DOUBLE' got 'Type.INTEGER'\n"
    )
    assert result.code == 1


def test_param_set_of_several_prints_one_line_each_and_applies_the_good_ones(
    param_node, param
) -> None:
    result = param("set", "/param_node", "frame", "x", "speed", "0.9", "count", "-1")
    assert result.code == 1
    assert result.out == "speed: Set parameter successful\n"
    assert result.err == (
        "frame: Setting parameter failed: Trying to set a read-only parameter: frame.\n"
        "count: Setting parameter failed: Parameter {count} doesn't comply with integer range.\n"
    )
    assert get(param, "speed") == "Double value is: 0.9\n"
    good = param("set", "/param_node", "speed", "1.5", "count", "7")
    assert (good.code, good.err) == (0, "")
    assert good.out == "speed: Set parameter successful\ncount: Set parameter successful\n"


def test_param_set_atomic_sets_all_or_none(param_node, param) -> None:
    refused = param("set", "/param_node", "speed", "4.0", "frame", "x", "--atomic")
    assert (refused.code, refused.out) == (1, "")
    assert refused.err == (
        "Setting parameters atomically failed: Trying to set a read-only parameter: frame.\n"
    )
    assert get(param, "speed") == "Double value is: 2.0\n"
    done = param("set", "--atomic", "/param_node", "speed", "4.0", "count", "9")
    assert (done.code, done.out, done.err) == (0, "Set parameters atomically successful\n", "")
    assert get(param, "speed") == "Double value is: 4.0\n"
    assert get(param, "count") == "Integer value is: 9\n"


def test_param_set_of_an_unknown_parameter_names_the_closest_one(param_node, param) -> None:
    result = param("set", "/param_node", "sped", "1.0")
    assert (result.code, result.out) == (1, "")
    assert result.err.startswith("Setting parameter failed: ")
    assert "(did you mean 'speed'" in result.err


def test_param_set_without_a_value_is_ros2s_one_line_error(param_node, param) -> None:
    assert_user_error(
        param("set", "/param_node", "speed"),
        "Parameters must be provided as name/value pairs: name value [name value ...]. "
        "Got 1 argument(s).",
    )
    typo = param("set", "/param_node", "--atomc", "1")
    assert typo.code == 2
    assert "No such option" in typo.err
    assert "Traceback" not in typo.err


# --- dump, load -------------------------------------------------------------------------------


def test_param_dump_prints_ros2s_yaml_and_output_dir_writes_it(
    param_node, param, tmp_path: Path
) -> None:
    result = param("dump", "/param_node")
    assert (result.code, result.out, result.err) == (0, DUMP + "\n", "")  # print()'s blank line
    (tmp_path / "out").mkdir()
    saved = param("dump", "/param_node", "--output-dir", str(tmp_path / "out"))
    assert saved.code == 0, saved
    assert saved.out == f"Saving to:  {tmp_path / 'out' / 'param_node.yaml'}\n"
    assert saved.err == "WARNING: '--output-dir' is deprecated; use redirection to save to a file\n"
    assert (tmp_path / "out" / "param_node.yaml").read_text() == DUMP


def test_param_dump_to_a_missing_folder_is_ros2s_error(param_node, param, tmp_path: Path) -> None:
    missing = str(tmp_path / "invalid_path")
    result = param("dump", "/param_node", "--output-dir", missing)
    assert result.out == ""
    assert assert_user_error(result) == f"'{missing}' is not a valid directory."
    assert not (tmp_path / "invalid_path").exists()


def test_param_load_of_a_dump_sets_each_parameter_and_says_so(
    param_node, param, tmp_path: Path
) -> None:
    path = tmp_path / "params.yaml"
    path.write_text(DUMP.replace("speed: 2.0", "speed: 3.25").replace("- 2.5", "- 7.5"))
    result = param("load", "/param_node", str(path))
    assert result.code == 1  # the read-only frame is refused, the rest applied
    expected = [f"Set parameter {name} successful" for name in NAMES if name != "frame"]
    assert sorted(result.out.splitlines()) == sorted(expected)
    assert result.err == (
        "Set parameter frame failed: Trying to set a read-only parameter: frame.\n"
    )
    assert get(param, "speed") == "Double value is: 3.25\n"
    assert get(param, "gains") == "Double values are: array('d', [1.0, 7.5])\n"
    assert get(param, "limits.max") == "Double value is: 9.5\n"


def test_param_load_uses_the_wildcard_section_unless_no_use_wildcard(
    param_node, param, tmp_path: Path
) -> None:
    path = tmp_path / "params.yaml"
    path.write_text(
        "/**:\n  ros__parameters:\n    shared: 4\n    speed: 1.0\n"
        "/param_node:\n  ros__parameters:\n    speed: 6.5\n"
        "/other_node:\n  ros__parameters:\n    count: 8\n"
    )
    narrow = param("load", "/param_node", str(path), "--no-use-wildcard")
    assert (narrow.code, narrow.out, narrow.err) == (0, "Set parameter speed successful\n", "")
    assert get(param, "shared") == "Integer value is: 0\n"
    assert get(param, "speed") == "Double value is: 6.5\n"

    wide = param("load", "/param_node", str(path))
    assert (wide.code, wide.err) == (0, "")
    assert wide.out == "Set parameter shared successful\nSet parameter speed successful\n"
    assert get(param, "shared") == "Integer value is: 4\n"
    assert get(param, "speed") == "Double value is: 6.5\n"  # the node's own section wins
    assert get(param, "count") == "Integer value is: 5\n"  # another node's section: untouched


def test_param_load_of_a_file_without_the_node_is_one_line_naming_what_it_has(
    param_node, param, tmp_path: Path
) -> None:
    path = tmp_path / "other.yaml"
    path.write_text("/other_node:\n  ros__parameters:\n    count: 8\n")
    assert_user_error(param("load", "/param_node", str(path)), "/param_node", "/other_node")
    wildcard_only = tmp_path / "wild.yaml"
    wildcard_only.write_text("/**:\n  ros__parameters:\n    shared: 2\n")
    assert_user_error(
        param("load", "/param_node", str(wildcard_only), "--no-use-wildcard"), "/param_node"
    )
    broken = tmp_path / "broken.yaml"
    broken.write_text("/param_node:\n  ros__parameters: [1, 2\n")
    assert_user_error(param("load", "/param_node", str(broken)), str(broken))
    assert get(param, "shared") == "Integer value is: 0\n"


# --- describe, delete -------------------------------------------------------------------------


def test_param_describe_prints_ros2s_type_description_and_constraints(param_node, param) -> None:
    result = param("describe", "/param_node", "count", "ratio", "frame", "speed")
    assert (result.code, result.err) == (0, "")
    assert result.out == (
        "Parameter name: count\n"
        "  Type: integer\n"
        "  Description: how many\n"
        "  Constraints:\n"
        "    Min value: 0\n"
        "    Max value: 10\n"
        "    Step: 1\n"
        "Parameter name: ratio\n"
        "  Type: double\n"
        "  Constraints:\n"
        "    Min value: 0.0\n"
        "    Max value: 1.0\n"
        "Parameter name: frame\n"
        "  Type: string\n"
        "  Constraints:\n"
        "    Read only: true\n"
        "    Additional constraints: fixed at start\n"
        "Parameter name: speed\n"
        "  Type: double\n"
        "  Constraints:\n"
    )
    line = assert_user_error(param("describe", "/param_node", "cont"), "cont")
    assert line.endswith("(did you mean 'count'?)")


def test_param_delete_unsets_a_dynamically_typed_parameter(param_node, param) -> None:
    result = param("delete", "/param_node", "anything")
    assert (result.code, result.out, result.err) == (0, "Deleted parameter successfully\n", "")
    assert_user_error(param("get", "/param_node", "anything"), "Parameter not set")
    assert "  anything\n" not in param("list", "/param_node").out
    line = assert_user_error(param("delete", "/param_node", "shard"), "Deleting parameter failed")
    assert line.endswith("(did you mean 'shared'?)")


def test_param_delete_of_a_statically_typed_parameter_is_refused_as_rclpy_does(
    param_node, param
) -> None:
    result = param("delete", "/param_node", "speed")
    assert result.err == "Deleting parameter failed: Static parameter cannot be undeclared\n"
    assert get(param, "speed") == "Double value is: 2.0\n"


# --- the seed ---------------------------------------------------------------------------------

PERIOD_CHANGED = r"\[timer_node\]: Timer period changed to 0\.5 s"


def test_the_seeds_param_set_changes_the_running_timer_nodes_period(processes, param) -> None:
    node = Watched(processes.rosl("run", "tutorial_pkg", "timer_node"))
    assert node.wait_for(r"\[timer_node\]: Timer period: 2\.0 s", "err", timeout=30.0), node.text(
        "err"
    )
    result = param("set", "/timer_node", "timer_period_s", "0.5")
    assert (result.code, result.out, result.err) == (0, "Set parameter successful\n", "")
    assert node.wait_for(PERIOD_CHANGED, "err", timeout=15.0), node.text("err")
    assert node.wait_for(r"Tick \d+ \(period 0\.5 s\)", "err", timeout=15.0), node.text("err")

    refused = param("set", "/timer_node", "timer_period_s", "-1.0")
    assert (refused.code, refused.out) == (1, "")
    assert refused.err == "Setting parameter failed: timer_period_s must be > 0\n"
    assert param("get", "/timer_node", "timer_period_s").out == "Double value is: 0.5\n"


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        (".nan", "ValueError: cannot convert float NaN to integer"),
        ("1.0e+300", "OverflowError: cannot convert float infinity to integer"),
    ],
    ids=["nan", "huge"],
)
def test_param_set_that_makes_the_nodes_callback_raise_fails_and_the_node_keeps_running(
    processes, param, value: str, reason: str
) -> None:
    # the tutorial's callback refuses <= 0 but turns nan/1e300 into an int: it raises
    node = Watched(processes.rosl("run", "tutorial_pkg", "timer_node", "--ros-args", "-p",
                                  "timer_period_s:=0.5"))  # fmt: skip
    assert node.wait_for(r"\[timer_node\]: Timer period: 0\.5 s", "err", timeout=30.0), node.text(
        "err"
    )

    failed = param("set", "/timer_node", "timer_period_s", value)

    assert (failed.code, failed.out) == (1, ""), failed
    assert failed.err == f"Setting parameter failed: {reason}\n"
    logged = "exception in callback for on_set_parameters: " + re.escape(reason)
    assert node.wait_for(logged, "err", timeout=15.0), node.text("err")
    assert param("get", "/timer_node", "timer_period_s").out == "Double value is: 0.5\n"
    ticks = len(node.matching(r"Tick \d+ \(period 0\.5 s\)", "err"))
    assert node.wait_for(r"Tick \d+ \(period 0\.5 s\)", "err", timeout=15.0, count=ticks + 1)
    assert node.interrupt() == 0, node.text("err")


HIDDEN_NODE = """
import rosl

rosl.init([])
node = rosl.Node("_hidden_params")
node.declare_parameter("level", 3)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def test_a_hidden_node_is_found_only_with_include_hidden_nodes(processes, param) -> None:
    Watched(processes.python(HIDDEN_NODE)).wait_ready()
    assert assert_user_error(param("get", "/_hidden_params", "level")) == "Node not found"
    assert assert_user_error(param("list", "/_hidden_params")) == "Node not found"
    found = param("get", "/_hidden_params", "level", "--include-hidden-nodes")
    assert (found.code, found.out, found.err) == (0, "Integer value is: 3\n", "")
    listed = param("list", "/_hidden_params", "--include-hidden-nodes")
    assert listed.out == "  level\n  use_sim_time\n"
