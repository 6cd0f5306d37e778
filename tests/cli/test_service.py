"""``rosl service ...`` against the tutorial's /count_images (``rosl run``), compared with ROS 2."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import SERVER
from tests.cli.conftest import Result, assert_user_error, run, timed, timed_after, wait_graph

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


WAITING = "waiting for service to become available..."


def test_call_with_nothing_serving_gives_up_within_the_timeout(processes) -> None:
    result, took, waited = timed_after(processes, WAITING, "service", "call", "/nobody",
                                       "std_srvs/srv/Trigger", "--timeout", "1")  # fmt: skip
    assert result.out == "waiting for service to become available...\n"
    assert assert_user_error(result) == "service /nobody not available after 1.0 s"
    assert took >= 1.0
    # the 1 s wait and the exit, not the default 5 s (the start-up is left out)
    assert waited < 4.0, waited


@pytest.mark.slow
def test_call_waits_five_seconds_by_default(processes) -> None:
    result, took, waited = timed_after(
        processes, WAITING, "service", "call", "/nobody", "std_srvs/srv/Trigger"
    )
    assert assert_user_error(result) == "service /nobody not available after 5.0 s"
    assert took >= 5.0
    assert waited < 9.0, waited  # the 5 s wait and the exit, not more


def test_call_of_a_misspelt_service_names_the_closest_after_the_wait(
    count_images, processes
) -> None:
    result, took, waited = timed_after(processes, WAITING, "service", "call", "/count_image",
                                       "tutorial_pkg/srv/CountImages", "{folder_path: /tmp}",
                                       "--timeout", "1")  # fmt: skip
    assert result.out == "waiting for service to become available...\n"
    assert assert_user_error(result) == (
        "service /count_image not available after 1.0 s; did you mean '/count_images'?"
    )
    assert took >= 1.0
    assert waited < 4.0, waited  # the 1 s wait and the exit (the start-up is left out)


def test_call_with_another_type_than_the_server_fails_at_once(count_images, processes) -> None:
    result, took = timed(processes, "service", "call", "/count_images", "std_srvs/srv/Trigger",
                         "--timeout", "30")  # fmt: skip
    assert result.out == ""
    assert assert_user_error(result) == (
        "service /count_images is of type tutorial_pkg/srv/CountImages, not std_srvs/srv/Trigger"
    )
    assert took < 20.0  # refused from the graph, not after waiting out the 30 s for an answer


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


def test_type_of_an_unknown_service_prints_nothing_and_exits_1_as_ros2(
    count_images, processes
) -> None:
    assert run(processes, "service", "type", "/count_imagez") == Result(1, "", "")


HIDDEN_SERVER = """
import rosl
from std_srvs.srv import Trigger

rosl.init([])
node = rosl.Node("echo_server", namespace="/my_ns")
node.create_service(Trigger, "_echo", lambda request, response: response)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def test_a_hidden_service_is_found_only_with_include_hidden_services(processes) -> None:
    processes.python(HIDDEN_SERVER)
    wait_graph(lambda g: g.count(SERVER, "/my_ns/_echo") == 1)
    assert run(processes, "service", "type", "/my_ns/_echo") == Result(1, "", "")
    shown = Result(0, "std_srvs/srv/Trigger\n", "")
    assert run(processes, "service", "type", "/my_ns/_echo", "--include-hidden-services") == shown
    # ros2 takes the flag before the verb
    assert run(processes, "service", "--include-hidden-services", "type", "/my_ns/_echo") == shown
    assert run(processes, "service", "find", "std_srvs/srv/Trigger") == Result(0, "", "")
    assert run(processes, "service", "--include-hidden-services", "find",
               "std_srvs/srv/Trigger") == Result(0, "/my_ns/_echo\n", "")  # fmt: skip
    listed = run(processes, "service", "--include-hidden-services", "list").out.splitlines()
    assert listed[0] == "/my_ns/_echo"
    assert "/my_ns/_echo" not in run(processes, "service", "list").out


def test_find_of_a_name_that_is_no_service_type_prints_nothing_and_exits_0(processes) -> None:
    assert run(processes, "service", "find", "not_a_service_type") == Result(0, "", "")


DIVIDER = """
import rosl
from std_srvs.srv import Trigger

rosl.init()
node = rosl.Node("divider")
node.create_service(Trigger, "divide", lambda request, response: 1 / 0)
rosl.spin(node)
"""


def test_call_of_a_server_whose_callback_raises_reports_its_error_at_once(processes) -> None:
    server = processes.python(DIVIDER)
    wait_graph(lambda g: g.count(SERVER, "/divide") == 1)
    # a long --timeout: the error must be the server's answer, not the wait running out
    result = run(processes, "service", "call", "/divide", "std_srvs/srv/Trigger", "--timeout", "20")
    assert result.out == "requester: making request: std_srvs.srv.Trigger_Request()\n\n"
    assert assert_user_error(result) == (
        "service /divide failed: ZeroDivisionError: division by zero"
    )
    assert server.poll() is None, "the server died"


def test_echo_shows_the_request_of_a_failed_call_and_keeps_running(processes) -> None:
    from tests.graph.support import Watched

    processes.python(DIVIDER)
    wait_graph(lambda g: g.count(SERVER, "/divide") == 1)
    echo = Watched(processes.rosl("service", "echo", "/divide", env={"NO_COLOR": "1"}))
    deadline = time.monotonic() + 60.0
    heard = False
    while not heard and time.monotonic() < deadline:  # until echo listens (bounded)
        failed = run(processes, "service", "call", "/divide", "--timeout", "20")
        assert_user_error(failed, "ZeroDivisionError")
        heard = echo.wait_for("event_type: REQUEST_SENT", timeout=5.0)
    assert heard, echo.text("err")
    assert echo.child.poll() is None, echo.text("err")
    assert echo.interrupt(timeout=10.0) is not None
    assert "Traceback" not in echo.text("err"), echo.text("err")
    assert "RESPONSE_SENT" not in echo.text(), echo.text()
