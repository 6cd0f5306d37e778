"""Bad world and robot files and bad options: one line naming file:line and what is expected."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from rosl.sim.errors import WorldFileError
from rosl.sim.worldfile import load_world

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.launch.support import Rosl

BURGER = "{name: burger, model: turtlebot3_burger, pose: [0.0, 0.0, 0.0]}"

# (world file, line of the error, fragments the one stderr line must contain)
BAD_WORLDS = {
    "unknown_key": (
        f"format: rosl-world/1\nname: typo\nrobot:\n  - {BURGER}\n",
        3,
        ["unknown key 'robot'", "did you mean 'robots'?"],
    ),
    "unknown_shape_key": (
        "format: rosl-world/1\nstatic:\n  - {type: cylinder, center: [2, 0], radus: 0.3}\n",
        3,
        ["unknown key 'radus'", "did you mean 'radius'?"],
    ),
    "wrong_type": (
        "format: rosl-world/1\nstatic:\n  - {type: cylinder, center: [2, 0],\n     radius: big}\n",
        4,
        ["'radius' must be a number", "'big'"],
    ),
    "wrong_pose_type": (
        "format: rosl-world/1\nrobots:\n  - {model: turtlebot3_burger, pose: [1, 2]}\n",
        3,
        ["'pose' must be [x, y, yaw]"],
    ),
    "negative_radius": (
        "format: rosl-world/1\nstatic:\n  - {type: cylinder, center: [2, 0], radius: -0.5}\n",
        3,
        ["'radius' must be greater than 0", "-0.5"],
    ),
    "overlapping_spawn": (
        "format: rosl-world/1\nrobots:\n"
        "  - {name: a, model: turtlebot3_burger, pose: [0.0, 0.0, 0.0]}\n"
        "  - {name: b, model: turtlebot3_burger, namespace: b,\n"
        "     pose: [0.15, 0.0, 0.0]}\n",
        5,
        ["robot 'b' overlaps robot 'a'"],
    ),
    "inside_a_wall": (
        "format: rosl-world/1\nstatic:\n"
        "  - {type: box, name: wall, center: [0.5, 0.0], size: [0.2, 3.0]}\n"
        "robots:\n  - {name: burger, model: turtlebot3_burger, pose: [0.45, 0.0, 0.0]}\n",
        5,
        ["robot 'burger' is spawned inside 'wall'"],
    ),
    "missing_model": (
        "format: rosl-world/1\nrobots:\n  - {model: turtlebot4, pose: [0, 0, 0]}\n",
        3,
        ["robot model 'turtlebot4' not found", "dolly", "turtlebot3_burger"],
    ),
    "format_version": (
        "# a world from the future\nformat: rosl-world/2\n",
        2,
        ["format must be 'rosl-world/1'", "'rosl-world/2'"],
    ),
    "invalid_yaml": (
        "format: rosl-world/1\nstatic:\n  - {type: cylinder, center: [0, 0], radius: 1\n",
        4,
        ["not valid YAML"],
    ),
}


def one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err, err
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize("case", sorted(BAD_WORLDS))
def test_rosl_sim_refuses_a_bad_world_file_in_one_line_naming_file_and_line(
    rosl: Rosl, write_world: Callable[..., Path], case: str
) -> None:
    text, line, fragments = BAD_WORLDS[case]
    path = write_world(text, name=f"{case}.yaml")
    code, out, err = rosl.run("sim", str(path), "--duration", "0.1", "--headless")
    assert code == 1, out + err
    message = one_line(err)
    assert message.startswith(f"{path}:{line}: "), message
    for fragment in fragments:
        assert fragment in message, message


def test_a_bad_robot_file_is_named_with_its_own_line(
    rosl: Rosl, write_world: Callable[..., Path]
) -> None:
    path = write_world(
        "format: rosl-world/1\nrobots:\n  - {model: cart, pose: [0, 0, 0]}\n",
        robots={
            "cart": """
                format: rosl-robot/1
                footprint: {type: circle, radius: 0.2}
                drive: {wheel_separation: 0.3, wheel_radius: -0.05}
            """
        },
    )
    code, _, err = rosl.run("sim", str(path), "--duration", "0.1", "--headless")
    assert code == 1
    message = one_line(err)
    assert message.startswith(f"{path.parent / 'robots' / 'cart.yaml'}:3: "), message
    assert "'wheel_radius' must be greater than 0" in message


def test_the_rosl_sim_package_executable_reports_a_bad_world_in_one_line(
    rosl: Rosl, write_world: Callable[..., Path]
) -> None:
    text, line, fragments = BAD_WORLDS["unknown_key"]
    path = write_world(text)
    code, _, err = rosl.run("run", "rosl_sim", "sim", str(path), "--headless")
    assert code == 1
    message = one_line(err)
    assert f"{path}:{line}: " in message
    assert fragments[0] in message


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        (["--real-time-factor", "0"], "--real-time-factor must be greater than 0"),
        (["--real-time-factor", "-2"], "--real-time-factor must be greater than 0"),
        (["--render", "run.gif"], "must be a .svg or .png"),
        (["--record", "{full}"], "already exists and is not empty"),
        (["--duration", "0"], "--duration must be greater than 0"),
        (["--fast", "--lockstep-timeout", "0"], "--lockstep-timeout must be greater than 0"),
        (["--clock-rate", "0"], "--clock-rate must be greater than 0 Hz"),
        (["--clock-rate", "nan"], "--clock-rate must be greater than 0 Hz"),
        (["--clock-rate", "inf"], "--clock-rate must be greater than 0 Hz (and finite), not inf"),
        (["--real-time-factor", "nan"], "--real-time-factor must be greater than 0"),
        (["--real-time-factor", "inf"], "--real-time-factor must be greater than 0"),
        (["--duration", "inf"], "--duration must be greater than 0 seconds (and finite)"),
        (["--duration", "nan"], "--duration must be greater than 0 seconds (and finite)"),
        (["--fast", "--lockstep-timeout", "nan"], "--lockstep-timeout must be greater than 0"),
        (["no_such_world"], "world 'no_such_world' not found"),
    ],
    ids=[
        "rtf-zero",
        "rtf-negative",
        "gif",
        "record-full",
        "duration",
        "lockstep",
        "clock-zero",
        "clock-nan",
        "clock-inf",
        "rtf-nan",
        "rtf-inf",
        "duration-inf",
        "duration-nan",
        "lockstep-nan",
        "world",
    ],
)
def test_rosl_sim_refuses_bad_options_in_one_line_before_starting(
    rosl: Rosl, tmp_path: Path, options: list[str], fragment: str
) -> None:
    full = tmp_path / "old_bag"
    full.mkdir()
    (full / "metadata.yaml").write_text("keep me\n")
    world = [] if options == ["no_such_world"] else ["empty"]
    args = [o.replace("{full}", str(full)) for o in options]
    code, out, err = rosl.run("sim", *world, *args, "--headless")
    assert code == 1, out + err
    assert fragment in one_line(err)
    assert out == ""  # nothing ran, so no summary
    assert (full / "metadata.yaml").read_text() == "keep me\n"
    assert sorted(p.name for p in tmp_path.iterdir() if p.name != "log") == ["cwd", "old_bag"]


# --- the library: every problem is a WorldFileError "file:line: what is expected" -------------

WORLD_PROBLEMS = {
    # not a mapping / not a list where one is expected: a traceback today
    "static_not_a_list": ("format: rosl-world/1\nstatic: 5\n", 2),
    "physics_not_a_mapping": ("format: rosl-world/1\nphysics: 0.01\n", 2),
    "robots_a_mapping": ("format: rosl-world/1\nrobots: {model: turtlebot3_burger}\n", 2),
    "robot_not_a_mapping": ("format: rosl-world/1\nrobots:\n  - turtlebot3_burger\n", 3),
    "shape_not_a_mapping": ("format: rosl-world/1\nstatic:\n  - cylinder\n", 3),
    "grid_shape_not_a_mapping": (
        "format: rosl-world/1\nstatic:\n"
        "  - {type: grid, shape: 5, origin: [0, 0], step: [1, 1], count: [2, 2]}\n",
        3,
    ),
    # values that are accepted silently today
    "nan_pose": (
        "format: rosl-world/1\nrobots:\n  - {model: turtlebot3_burger, pose: [.nan, 0, 0]}\n",
        3,
    ),
    "infinite_center": (
        "format: rosl-world/1\nstatic:\n  - {type: cylinder, center: [.inf, 0], radius: 1}\n",
        3,
    ),
    "kinematic_text": (
        "format: rosl-world/1\ndynamic:\n"
        '  - {type: cylinder, center: [3, 0], radius: 1, kinematic: "false"}\n',
        3,
    ),
    "fractional_sides": (
        "format: rosl-world/1\nstatic:\n"
        "  - {type: regular_polygon, center: [3, 0], sides: 3.7, circumradius: 1}\n",
        3,
    ),
}

ROBOT_PROBLEMS = {
    "footprint_not_a_mapping": (
        "footprint: 5\ndrive: {wheel_separation: 0.2, wheel_radius: 0.03}\n",
        2,
    ),
    "drive_not_a_mapping": ("footprint: {type: circle, radius: 0.1}\ndrive: [0.2, 0.03]\n", 3),
    "frames_a_list": (
        "footprint: {type: circle, radius: 0.1}\n"
        "drive: {wheel_separation: 0.2, wheel_radius: 0.03}\nframes: [base_link]\n",
        4,
    ),
    "odom_rate_text": (
        "footprint: {type: circle, radius: 0.1}\n"
        "drive: {wheel_separation: 0.2, wheel_radius: 0.03, odom: {rate: fast}}\n",
        3,
    ),
    "odom_unknown_key": (
        "footprint: {type: circle, radius: 0.1}\n"
        "drive: {wheel_separation: 0.2, wheel_radius: 0.03, odom: {rat: 30}}\n",
        3,
    ),
    "negative_box_footprint": (
        "footprint: {type: box, size: [-1.0, 0.5]}\n"
        "drive: {wheel_separation: 0.2, wheel_radius: 0.03}\n",
        2,
    ),
    "lidar_range_min_above_max": (
        "footprint: {type: circle, radius: 0.1}\n"
        "drive: {wheel_separation: 0.2, wheel_radius: 0.03}\nsensors:\n"
        "  - {type: lidar2d, frame_id: laser, topic: scan, rate: 5, samples: 10,\n"
        "     angle_min: -1.0, angle_max: 1.0, range_min: 5.0, range_max: 2.0}\n",
        6,
    ),
}


@pytest.mark.parametrize("case", sorted(WORLD_PROBLEMS))
def test_load_world_reports_a_world_problem_as_file_and_line(
    write_world: Callable[..., Path], case: str
) -> None:
    text, line = WORLD_PROBLEMS[case]
    path = write_world(text, name=f"{case}.yaml")
    with pytest.raises(WorldFileError) as caught:
        load_world(path)
    assert str(caught.value).startswith(f"{path}:{line}: "), str(caught.value)


@pytest.mark.parametrize("case", sorted(ROBOT_PROBLEMS))
def test_load_world_reports_a_robot_file_problem_as_file_and_line(
    write_world: Callable[..., Path], case: str
) -> None:
    text, line = ROBOT_PROBLEMS[case]
    world = write_world(
        "format: rosl-world/1\nrobots:\n  - {model: cart, pose: [0, 0, 0]}\n",
        name=f"{case}.yaml",
        robots={"cart": "format: rosl-robot/1\n" + text},
    )
    robot_file = world.parent / "robots" / "cart.yaml"
    with pytest.raises(WorldFileError) as caught:
        load_world(world)
    message = str(caught.value)
    assert re.match(rf"{re.escape(str(robot_file))}:{line}: ", message), message
