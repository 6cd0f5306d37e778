"""rclpy.parameter's module functions under rosl (``rosl.node.parameter_values``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

import rosl.compat

if TYPE_CHECKING:
    from pathlib import Path

rosl.compat.install()


def test_parameter_separator_and_value_helpers_match_rclpy() -> None:
    from rclpy.parameter import (
        PARAMETER_SEPARATOR_STRING,
        Parameter,
        get_parameter_value,
        parameter_value_to_python,
    )

    assert PARAMETER_SEPARATOR_STRING == "."
    assert parameter_value_to_python(get_parameter_value("1.5")) == 1.5
    assert parameter_value_to_python(get_parameter_value("[1, 2]")) == [1, 2]
    assert parameter_value_to_python(get_parameter_value("[1, 'a']")) == "[1, 'a']"
    assert get_parameter_value("true").type == Parameter.Type.BOOL


def test_parameter_dict_from_yaml_file_flattens_nested_names_and_puts_the_wildcard_first(
    tmp_path: Path,
) -> None:
    from rclpy.parameter import parameter_dict_from_yaml_file, parameter_value_to_python

    path = tmp_path / "params.yaml"
    path.write_text(
        "/**:\n  ros__parameters:\n    rate: 5\n    frame: map\n"
        "talker:\n  ros__parameters:\n    rate: 10.0\n    pid:\n      kp: 1.5\n      gains: [1, 2]\n"
    )
    values = parameter_dict_from_yaml_file(path, use_wildcard=True)
    assert sorted(values) == ["frame", "pid.gains", "pid.kp", "rate"]
    assert values["pid.kp"].name == "pid.kp"
    assert parameter_value_to_python(values["rate"].value) == 10.0  # the node's own wins
    assert parameter_value_to_python(values["pid.gains"].value) == [1, 2]
    only = parameter_dict_from_yaml_file(path, target_nodes=["talker"], namespace="ns.")
    assert sorted(only) == ["ns.pid.gains", "ns.pid.kp", "ns.rate"]


def test_parameter_dict_from_yaml_file_errors_are_one_line_naming_the_file(
    tmp_path: Path,
) -> None:
    from rclpy.parameter import parameter_dict_from_yaml_file

    from rosl.errors import RoslError

    path = tmp_path / "params.yaml"
    path.write_text("talker:\n  ros__parameters:\n    rate: 5\n")
    with pytest.raises(RoslError, match="does not contain parameters for listener") as caught:
        parameter_dict_from_yaml_file(path, target_nodes=["listener"])
    assert str(path) in str(caught.value)
    path.write_text("talker:\n  rate: 5\n")
    with pytest.raises(RoslError, match="section 'talker' has no 'ros__parameters:' mapping"):
        parameter_dict_from_yaml_file(path)
    path.write_text("talker: [unclosed\n")
    with pytest.raises(RoslError, match="not a YAML parameter file") as caught:
        parameter_dict_from_yaml_file(path)
    assert "\n" not in str(caught.value)
