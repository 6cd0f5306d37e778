"""``rosl service ...`` against the tutorial's /count_images (``rosl run``), compared with ROS 2."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import SERVER
from tests.cli.conftest import Result, assert_user_error, run, timed, wait_graph

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

PARAMETER_SERVICES = [
    ("describe_parameters", "DescribeParameters"),
    ("get_parameter_types", "GetParameterTypes"),
    ("get_parameters", "GetParameters"),
    ("list_parameters", "ListParameters"),
    ("set_parameters", "SetParameters"),
    ("set_parameters_atomically", "SetParametersAtomically"),
]


@pytest.fixture
def count_images(processes: Processes) -> None:
    """The tutorial's /count_images server, started as a user would: ``rosl run``."""
    processes.rosl("run", "tutorial_pkg", "count_images")
    wait_graph(lambda g: g.count(SERVER, "/count_images/set_parameters_atomically") == 1)


@pytest.fixture
def pictures(tmp_path: Path) -> Path:
    folder = tmp_path / "pictures"
    folder.mkdir()
    for name in ("a.png", "b.jpg", "notes.txt"):
        (folder / name).write_bytes(b"-")
    return folder


def test_list_prints_every_service_with_types_and_count_as_ros2(count_images, processes) -> None:
    names = ["/count_images"] + [f"/count_images/{name}" for name, _ in PARAMETER_SERVICES]
    assert run(processes, "service", "list") == Result(0, "\n".join(names) + "\n", "")
    typed = "/count_images [tutorial_pkg/srv/CountImages]\n" + "".join(
        f"/count_images/{name} [rcl_interfaces/srv/{kind}]\n" for name, kind in PARAMETER_SERVICES
    )
    assert run(processes, "service", "list", "-t") == Result(0, typed, "")
    assert run(processes, "service", "list", "-c") == Result(0, "7\n", "")


def test_type_and_find_print_what_ros2_prints(count_images, processes) -> None:
    assert run(processes, "service", "type", "/count_images") == Result(
        0, "tutorial_pkg/srv/CountImages\n", ""
    )
    found = Result(0, "/count_images\n", "")
    assert run(processes, "service", "find", "tutorial_pkg/srv/CountImages") == found
    assert run(processes, "service", "find", "tutorial_pkg/CountImages") == found
    assert run(processes, "service", "find", "-c", "rcl_interfaces/srv/GetParameters") == Result(
        0, "1\n", ""
    )


def test_call_prints_ros2s_request_and_response_lines(count_images, processes, pictures) -> None:
    result = run(processes, "service", "call", "/count_images", "tutorial_pkg/srv/CountImages",
                 f"{{folder_path: '{pictures}'}}")  # fmt: skip
    assert result == Result(
        0,
        f"requester: making request: tutorial_pkg.srv.CountImages_Request("
        f"folder_path='{pictures}')\n\n"
        "response:\n"
        f"tutorial_pkg.srv.CountImages_Response(count=2, message='2 image(s) in {pictures}')\n\n",
        "",
    )
    # ros2's short type spelling, and no type at all (the graph knows it)
    short = run(processes, "service", "call", "/count_images", "tutorial_pkg/CountImages",
                f"{{folder_path: '{pictures}'}}")  # fmt: skip
    untyped = run(processes, "service", "call", "/count_images", f"{{folder_path: '{pictures}'}}")
    assert short == untyped == result


def test_call_with_nothing_serving_gives_up_within_the_timeout(processes) -> None:
    result, took = timed(processes, "service", "call", "/nobody", "std_srvs/srv/Trigger",
                         "--timeout", "1")  # fmt: skip
    assert result.out == "waiting for service to become available...\n"
    assert assert_user_error(result) == "service /nobody not available after 1.0 s"
    assert 1.0 <= took < 4.0


@pytest.mark.slow
def test_call_waits_five_seconds_by_default(processes) -> None:
    result, took = timed(processes, "service", "call", "/nobody", "std_srvs/srv/Trigger")
    assert assert_user_error(result) == "service /nobody not available after 5.0 s"
    assert 5.0 <= took < 8.0


def test_call_of_a_misspelt_service_names_the_closest_after_the_wait(
    count_images, processes
) -> None:
    result, took = timed(processes, "service", "call", "/count_image",
                         "tutorial_pkg/srv/CountImages", "{folder_path: /tmp}",
                         "--timeout", "1")  # fmt: skip
    assert result.out == "waiting for service to become available...\n"
    assert assert_user_error(result) == (
        "service /count_image not available after 1.0 s; did you mean '/count_images'?"
    )
    assert took < 4.0


def test_call_with_another_type_than_the_server_fails_at_once(count_images, processes) -> None:
    result, took = timed(processes, "service", "call", "/count_images", "std_srvs/srv/Trigger")
    assert result.out == ""
    assert assert_user_error(result) == (
        "service /count_images is of type tutorial_pkg/srv/CountImages, not std_srvs/srv/Trigger"
    )
    assert took < 3.0  # not the 5 s answer timeout


def test_call_sends_a_number_for_a_string_field_as_its_text_as_ros2_does(
    count_images, processes
) -> None:
    call = run(processes, "service", "call", "/count_images", "tutorial_pkg/srv/CountImages",
               "{folder_path: 5}")  # fmt: skip
    assert call.code == 0, call.err
    assert "message='not a folder: 5'" in call.out
    unknown = run(processes, "service", "call", "/count_images", "tutorial_pkg/srv/CountImages",
                  "{folder: x}")  # fmt: skip
    assert_user_error(unknown, "Failed to populate field:", "no field 'folder'", "folder_path")


def test_type_of_an_unknown_service_names_the_closest(count_images, processes) -> None:
    result = run(processes, "service", "type", "/count_imagez")
    assert result.out == ""
    assert_user_error(result, "Unknown service '/count_imagez'", "'/count_images'")
