"""``--ros-args`` parsing and name rules, with no bus."""

from __future__ import annotations

import pytest

from rosl.node import names, ros_args
from rosl.node.errors import InvalidNameError, RosArgsError


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1.5", 1.5),
        ("3", 3),
        ("true", True),
        ("False", False),
        ("[1,2]", [1, 2]),
        ("[0.5, 1]", [0.5, 1]),
        ("['a', 'b']", ["a", "b"]),
        ("hello", "hello"),
        ("'3'", "3"),
        ("", ""),
    ],
)
def test_parameter_values_are_parsed_as_yaml(text, value):
    parsed = ros_args.parse_value(text)
    assert parsed == value
    assert type(parsed) is type(value)


def test_only_the_ros_args_section_is_parsed_and_the_rest_is_left_to_the_program():
    argv = ["prog", "--verbose", "--ros-args", "-p", "a:=1", "-r", "x:=y", "--", "file.txt"]
    parsed = ros_args.parse(argv)
    assert parsed.user_args == ["prog", "--verbose", "file.txt"]
    assert parsed.params == [(None, "a", 1)]
    assert parsed.remaps == [names.Remap("x", "y", None)]
    assert ros_args.remove_ros_args(argv) == ["prog", "--verbose", "file.txt"]


def test_node_prefixed_rules_and_log_levels_are_read():
    parsed = ros_args.parse(
        ["--ros-args", "-p", "cam:rate:=30", "--param", "gain:=2.0", "-r", "cam:image:=raw",
         "--log-level", "warn", "--log-level", "cam:=debug", "--disable-rosout-logs"]
    )  # fmt: skip
    assert parsed.params == [("cam", "rate", 30), (None, "gain", 2.0)]
    assert parsed.remaps == [names.Remap("image", "raw", "cam")]
    assert parsed.log_levels == {None: "warn", "cam": "debug"}
    assert parsed.enable_rosout is False
    assert parsed.overrides("/cam") == {"rate": 30, "gain": 2.0}
    assert parsed.overrides("/other") == {"gain": 2.0}


def test_node_and_namespace_renames_are_read():
    parsed = ros_args.parse(["--ros-args", "-r", "__node:=renamed", "-r", "__ns:=/robot1"])
    assert parsed.node_name("talker") == "renamed"
    assert parsed.namespace(None, "talker") == "/robot1"


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["--ros-args", "--nope"], "unknown ROS argument '--nope'"),
        (["--ros-args", "-p"], "'-p' needs a value"),
        (["--ros-args", "-p", "novalue"], "expected name:=value"),
        (["--ros-args", "-p", ":=3"], "the name before ':=' is empty"),
        (["--ros-args", "-r", "a:="], "nothing after ':='"),
        (["--ros-args", "--log-level", "loud"], "--log-level 'loud'"),
        (["--ros-args", "--params-file", "/no/such/file.yaml"], "no such file"),
    ],
)
def test_malformed_ros_args_raise_errors_naming_the_problem(argv, fragment):
    with pytest.raises(RosArgsError) as err:
        ros_args.parse(argv)
    assert fragment in str(err.value)


def test_a_params_file_with_bad_yaml_names_the_file_and_line(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("/**:\n  ros__parameters:\n    a: [1, 2\n")
    with pytest.raises(RosArgsError) as err:
        ros_args.parse(["--ros-args", "--params-file", str(path)])
    assert str(path) in str(err.value)


def test_params_file_node_sections_win_over_wildcards_and_nested_keys_use_dots(tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(
        "/robot/cam:\n  ros__parameters:\n    fps: 60\n"
        "/robot/*:\n  ros__parameters:\n    fps: 15\n    lens: {focal: 3.5}\n"
        "/**:\n  ros__parameters:\n    fps: 30\n    frame: base\n"
    )
    assert ros_args.params_from_file(path, "/robot/cam") == {
        "fps": 60,
        "lens.focal": 3.5,
        "frame": "base",
    }
    assert ros_args.params_from_file(path, "/robot/lidar")["lens.focal"] == 3.5
    assert ros_args.params_from_file(path, "/other") == {"fps": 30, "frame": "base"}


@pytest.mark.parametrize(
    ("name", "namespace", "expanded"),
    [
        ("chatter", "/", "/chatter"),
        ("chatter", "/robot", "/robot/chatter"),
        ("/chatter", "/robot", "/chatter"),
        ("~/status", "/robot", "/robot/node/status"),
        ("~/status", "/", "/node/status"),
        ("{node}/x", "/a", "/a/node/x"),
        ("{ns}/x", "/a/b", "/a/b/x"),
    ],
)
def test_names_expand_as_rcl_does(name, namespace, expanded):
    assert names.expand(name, "node", namespace) == expanded


def test_remap_rules_match_the_expanded_name():
    rules = [names.Remap("chatter", "other"), names.Remap("/abs", "~/mine")]
    assert names.remap("/ns/chatter", rules, "n", "/ns") == "/ns/other"
    assert names.remap("/abs", rules, "n", "/ns") == "/ns/n/mine"
    assert names.remap("/chatter", rules, "n", "/ns") == "/chatter"


@pytest.mark.parametrize("bad", ["a b", "a-b", "1a", "a//b", "/a/", "x.y"])
def test_invalid_names_are_rejected(bad):
    with pytest.raises(InvalidNameError):
        names.validate_full_name("/" + bad if not bad.startswith("/") else bad)
