"""``rosl interface``: list, packages, package, show and proto, as ``ros2 interface`` does."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import Result, assert_user_error
from tests.conftest import REPO

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

SHIPPED = REPO / "interfaces"
PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string",
}  # fmt: skip


# --- an independent rendering of `ros2 interface show`, from the shipped files ---------------


def _split_comment(line: str) -> str:
    return line.split("#", 1)[0]


def _nested_file(base: str, package: str) -> Path | None:
    """The .msg file a field type refers to, or None for primitives."""
    base = re.split(r"[\[<]", base, maxsplit=1)[0]
    if base in PRIMITIVES:
        return None
    parts = base.split("/")
    if len(parts) == 1:
        own = SHIPPED / package / "msg" / f"{base}.msg"
        return own if own.is_file() or base != "Header" else SHIPPED / "std_msgs/msg/Header.msg"
    return SHIPPED / parts[0] / "msg" / f"{parts[-1]}.msg"


def expected_show(
    path: Path, *, comments: bool = True, nested_comments: bool = False, level: int = 0
) -> str:
    """Top-level lines verbatim; after each message field, its definition one TAB deeper."""
    package = path.parent.parent.name
    out = []
    for raw in path.read_text().splitlines():
        code = _split_comment(raw).strip()
        if comments:
            text = raw.rstrip()
        elif not code:
            continue
        else:
            text = code
        out.append("\t" * level + text if text else "")
        if code and code != "---" and "=" not in code:
            nested = _nested_file(code.split()[0], package)
            if nested is not None:
                out.append(
                    expected_show(
                        nested,
                        comments=nested_comments,
                        nested_comments=nested_comments,
                        level=level + 1,
                    ).rstrip("\n")
                )
    return "\n".join(out) + "\n"


# --- list / packages / package -----------------------------------------------------------------


def _sections(out: str) -> dict[str, list[str]]:
    sections: dict[str, list[str]] = {}
    current = None
    for line in out.splitlines():
        if not line.startswith(" "):
            current = line
            sections[current] = []
        else:
            assert current is not None, line
            sections[current].append(line)
    return sections


def test_interface_list_prints_messages_services_and_actions_sections(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "list")
    assert result.code == 0
    assert result.out.startswith("Messages:\n    ")
    sections = _sections(result.out)
    assert list(sections) == ["Messages:", "Services:", "Actions:"]
    kinds = {"Messages:": "msg", "Services:": "srv", "Actions:": "action"}
    for title, lines in sections.items():
        pattern = re.compile(rf"^    [a-z][a-z0-9_]*/{kinds[title]}/[A-Z][A-Za-z0-9]*$")
        assert all(pattern.match(line) for line in lines), lines
        assert lines == sorted(lines)
    assert "    std_msgs/msg/String" in sections["Messages:"]
    assert "    geometry_msgs/msg/Twist" in sections["Messages:"]
    assert "    std_srvs/srv/Trigger" in sections["Services:"]


def test_interface_list_only_msgs_prints_only_the_messages(rosl: Callable[..., Result]) -> None:
    result = rosl("interface", "list", "-m")
    assert result.code == 0
    sections = _sections(result.out)
    assert list(sections) == ["Messages:"]
    assert "    std_msgs/msg/String" in sections["Messages:"]


def test_interface_list_only_srvs_prints_only_the_services(rosl: Callable[..., Result]) -> None:
    result = rosl("interface", "list", "--only-srvs")
    assert result.code == 0
    sections = _sections(result.out)
    assert list(sections) == ["Services:"]
    assert "    std_srvs/srv/SetBool" in sections["Services:"]
    assert not any("/msg/" in line for line in sections["Services:"])


def test_interface_list_includes_a_workspace_package(
    rosl: Callable[..., Result], make_package: Callable[..., Path]
) -> None:
    make_package("my_ifaces", {"msg/Reading.msg": "float64 value\n", "srv/Reset.srv": "---\n"})
    sections = _sections(rosl("interface", "list").out)
    assert "    my_ifaces/msg/Reading" in sections["Messages:"]
    assert "    my_ifaces/srv/Reset" in sections["Services:"]


def test_interface_packages_prints_sorted_package_names(
    rosl: Callable[..., Result], make_package: Callable[..., Path]
) -> None:
    make_package("my_ifaces", {"msg/Reading.msg": "float64 value\n"})
    make_package("no_ifaces", {"no_ifaces/__init__.py": ""})
    result = rosl("interface", "packages")
    assert result.code == 0
    names = result.out.splitlines()
    assert names == sorted(names)
    assert {"std_msgs", "std_srvs", "geometry_msgs", "my_ifaces"} <= set(names)
    assert "no_ifaces" not in names


def test_interface_packages_only_srvs_leaves_out_message_only_packages(
    rosl: Callable[..., Result],
) -> None:
    names = rosl("interface", "packages", "-s").out.splitlines()
    assert "std_srvs" in names
    assert "geometry_msgs" not in names


def test_interface_package_std_srvs_prints_its_three_services(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "package", "std_srvs")
    assert result.code == 0
    assert result.out == "std_srvs/srv/Empty\nstd_srvs/srv/SetBool\nstd_srvs/srv/Trigger\n"
    assert result.err == ""


def test_interface_package_only_msgs_of_a_service_package_prints_nothing(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "package", "std_srvs", "-m")
    assert result.code == 0
    assert result.out == ""


def test_interface_package_of_an_unknown_package_is_one_line(
    rosl: Callable[..., Result],
) -> None:
    assert_user_error(rosl("interface", "package", "std_srv"), "std_srv", "did you mean")


# --- show --------------------------------------------------------------------------------------


def test_interface_show_twist_prints_the_file_with_nested_vector3_one_tab_deep(
    rosl: Callable[..., Result],
) -> None:
    twist = SHIPPED / "geometry_msgs" / "msg" / "Twist.msg"
    vector3 = SHIPPED / "geometry_msgs" / "msg" / "Vector3.msg"
    expected = []
    for line in twist.read_text().splitlines():
        expected.append(line.rstrip())
        if line.startswith("Vector3"):
            expected += [
                "\t" + _split_comment(v).strip()
                for v in vector3.read_text().splitlines()
                if _split_comment(v).strip()
            ]
    result = rosl("interface", "show", "geometry_msgs/msg/Twist")
    assert result.code == 0
    assert result.out == "\n".join(expected) + "\n"
    assert result.out == expected_show(twist)
    assert "\tfloat64 x\n\tfloat64 y\n\tfloat64 z\n" in result.out
    assert result.err == ""


def test_interface_show_nests_two_levels_with_two_tabs(rosl: Callable[..., Result]) -> None:
    scan = SHIPPED / "sensor_msgs" / "msg" / "LaserScan.msg"
    result = rosl("interface", "show", "sensor_msgs/msg/LaserScan")
    assert result.code == 0
    assert result.out == expected_show(scan)
    lines = result.out.splitlines()
    stamp = lines.index("\tbuiltin_interfaces/Time stamp")
    assert lines[stamp + 1 : stamp + 3] == ["\t\tint32 sec", "\t\tuint32 nanosec"]
    assert "\tstring frame_id" in lines


def test_interface_show_no_comments_drops_comments_and_blank_lines_everywhere(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "show", "--no-comments", "sensor_msgs/msg/LaserScan")
    assert result.code == 0
    scan = SHIPPED / "sensor_msgs" / "msg" / "LaserScan.msg"
    assert result.out == expected_show(scan, comments=False)
    assert "#" not in result.out
    assert "\n\n" not in result.out
    assert all(line.strip() for line in result.out.splitlines())
    assert result.out.splitlines()[0] == "std_msgs/Header header"


def test_interface_show_all_comments_keeps_the_nested_comments(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "show", "--all-comments", "geometry_msgs/msg/Twist")
    assert result.code == 0
    twist = SHIPPED / "geometry_msgs" / "msg" / "Twist.msg"
    assert result.out == expected_show(twist, nested_comments=True)
    assert "\t# A free vector in 3D space" in result.out


def test_interface_show_all_comments_with_no_comments_is_a_usage_error(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "show", "--all-comments", "--no-comments", "geometry_msgs/msg/Twist")
    assert result.code == 2
    assert result.out == ""
    assert "cannot be used together" in result.err
    assert "Traceback" not in result.err


@pytest.mark.parametrize(
    "spelling", ["std_msgs/msg/String", "std_msgs/String", "std_msgs.msg.String"]
)
def test_interface_show_accepts_every_spelling_of_a_message(
    rosl: Callable[..., Result], spelling: str
) -> None:
    result = rosl("interface", "show", spelling)
    assert result.code == 0
    assert result.out == (SHIPPED / "std_msgs" / "msg" / "String.msg").read_text()


@pytest.mark.parametrize("spelling", ["std_srvs/srv/Trigger", "std_srvs/Trigger"])
def test_interface_show_of_a_service_prints_both_halves_and_the_separator(
    rosl: Callable[..., Result], spelling: str
) -> None:
    result = rosl("interface", "show", spelling)
    assert result.code == 0
    assert result.out == (SHIPPED / "std_srvs" / "srv" / "Trigger.srv").read_text()
    assert "\n---\n" in result.out


def test_interface_show_dash_reads_the_type_from_stdin(
    rosl_process: Callable[..., Result],
) -> None:
    result = rosl_process("interface", "show", "-", stdin="geometry_msgs/msg/Twist\n")
    assert result.code == 0, result.err
    assert result.out == expected_show(SHIPPED / "geometry_msgs" / "msg" / "Twist.msg")


def test_interface_show_dash_with_nothing_on_stdin_is_one_line(
    rosl_process: Callable[..., Result],
) -> None:
    assert_user_error(rosl_process("interface", "show", "-", stdin=""), "standard input")


# --- proto -------------------------------------------------------------------------------------

TWIST_YAML = "linear:\n  x: 0.0\n  y: 0.0\n  z: 0.0\nangular:\n  x: 0.0\n  y: 0.0\n  z: 0.0\n"


def test_interface_proto_prints_the_quoted_yaml_of_a_default_message(
    rosl: Callable[..., Result],
) -> None:
    result = rosl("interface", "proto", "geometry_msgs/msg/Twist")
    assert result.code == 0
    assert result.out == f'"{TWIST_YAML}"\n'
    assert result.out.splitlines()[-1] == '"'


def test_interface_proto_no_quotes_prints_the_bare_yaml(rosl: Callable[..., Result]) -> None:
    result = rosl("interface", "proto", "--no-quotes", "geometry_msgs/msg/Twist")
    assert result.code == 0
    assert result.out == TWIST_YAML + "\n"


def test_interface_proto_of_a_string_message_matches_ros2(rosl: Callable[..., Result]) -> None:
    assert rosl("interface", "proto", "std_msgs/msg/String").out == "\"data: ''\n\"\n"


def test_interface_proto_of_a_service_shows_the_request(rosl: Callable[..., Result]) -> None:
    result = rosl("interface", "proto", "std_srvs/srv/SetBool")
    assert result.code == 0
    assert result.out == '"data: false\n"\n'
    assert "success" not in result.out


def test_interface_proto_of_a_service_written_pkg_slash_name_shows_the_request(
    rosl: Callable[..., Result],
) -> None:
    assert rosl("interface", "proto", "std_srvs/SetBool").out == '"data: false\n"\n'


# --- the tutorial: a package's own message, no build step -------------------------------------


def test_a_new_packages_message_is_shown_without_a_build_step(
    workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    created = rosl_process(
        "pkg", "create", "tutorial_pkg", "--dependencies", "std_msgs", "geometry_msgs",
        cwd=workspace / "src",
    )  # fmt: skip
    assert created.code == 0, created.err
    definition = "int32 counter\nfloat64 value\nstring label\n"
    (workspace / "src" / "tutorial_pkg" / "msg" / "MyData.msg").write_text(definition)
    for cwd in (workspace, workspace / "src"):
        shown = rosl_process("interface", "show", "tutorial_pkg/msg/MyData", cwd=cwd)
        assert shown.code == 0, shown.err
        assert shown.out == definition
        assert shown.err == ""
    listed = rosl_process("interface", "package", "tutorial_pkg", cwd=workspace)
    assert listed.out == "tutorial_pkg/msg/MyData\n"


# --- mistakes: one line, exit 1, no traceback --------------------------------------------------


def test_an_unknown_type_suggests_the_close_name(rosl: Callable[..., Result]) -> None:
    line = assert_user_error(
        rosl("interface", "show", "geometry_msgs/msg/Twst"), "geometry_msgs/msg/Twst"
    )
    assert "did you mean 'Twist'" in line


def test_an_unknown_type_is_one_line_from_the_real_command(
    rosl_process: Callable[..., Result],
) -> None:
    result = rosl_process("interface", "show", "geometry_msgs/msg/Twst")
    line = assert_user_error(result, "did you mean 'Twist'")
    assert result.out == ""
    assert line.startswith("unknown type 'geometry_msgs/msg/Twst'")


def test_an_unknown_package_in_a_type_is_named(rosl: Callable[..., Result]) -> None:
    line = assert_user_error(
        rosl("interface", "show", "geometri_msgs/msg/Twist"), "package 'geometri_msgs' not found"
    )
    assert "did you mean 'geometry_msgs'" in line


def test_an_invalid_type_name_is_one_line(rosl: Callable[..., Result]) -> None:
    assert_user_error(rosl("interface", "show", "geometry_msgs/msg/twist"), "invalid type name")


def test_a_misspelt_primitive_is_located_and_corrected(
    workspace: Path, make_package: Callable[..., Path], rosl_process: Callable[..., Result]
) -> None:
    make_package("tutorial_pkg", {"msg/MyData.msg": "int32 counter\nflaot64 value\n"})
    result = rosl_process("interface", "show", "tutorial_pkg/msg/MyData", cwd=workspace)
    line = assert_user_error(result)
    assert line == (
        "src/tutorial_pkg/msg/MyData.msg:2:1: unknown type 'flaot64' (did you mean 'float64'?)"
    )
    assert result.out == ""


def test_a_service_with_two_separators_is_located_at_the_second(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    make_package("svc_pkg", {"srv/Twice.srv": "int32 a\n---\nint32 b\n---\nint32 c\n"})
    line = assert_user_error(rosl("interface", "show", "svc_pkg/srv/Twice"))
    assert line.startswith("src/svc_pkg/srv/Twice.srv:4:1: more than one '---'")
    assert "line 2" in line


def test_a_reference_to_a_missing_type_names_the_package_folder_searched(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    folder = make_package("ref_pkg", {"msg/Holder.msg": "# holds a Foo\nFoo foo\n"})
    line = assert_user_error(rosl("interface", "show", "ref_pkg/msg/Holder"))
    assert line.startswith("src/ref_pkg/msg/Holder.msg:2:1: unknown type 'Foo'")
    assert "msg/Foo.msg" in line
    assert f"({folder.resolve()})" in line


def test_proto_of_an_unknown_type_is_one_line(rosl: Callable[..., Result]) -> None:
    assert_user_error(rosl("interface", "proto", "std_msgs/msg/Strin"), "did you mean 'String'")


@pytest.mark.parametrize(
    ("files", "shown", "cycle"),
    [
        ({"msg/Rec.msg": "Rec r\n"}, "loops/msg/Rec", "loops/msg/Rec -> loops/msg/Rec"),
        (
            {"msg/A.msg": "int32 x\nB b\n", "msg/B.msg": "A a\n"},
            "loops/msg/A",
            "loops/msg/A -> loops/msg/B -> loops/msg/A",
        ),
    ],
    ids=["self", "mutual"],
)
def test_interface_show_of_a_recursive_message_names_the_cycle(
    rosl: Callable[..., Result],
    make_package: Callable[..., Path],
    files: dict[str, str],
    shown: str,
    cycle: str,
) -> None:
    make_package("loops", files)
    line = assert_user_error(rosl("interface", "show", shown), "recursive message definition")
    assert line == f"recursive message definition: {cycle}"
