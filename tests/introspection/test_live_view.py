"""``rosl viz --serve``: the live world and the graph in a page rosl serves, seen as a user would.

A simulator (turtlebot3_world) runs with the robot driven in a circle, ``rosl viz --serve``
serves its page, and the tests read it over HTTP (the event stream, the files), in a real
headless chromium (the DOM and screenshots), and give it bad inputs. Screenshots are kept under
tests/artifacts/live_view/ (git-ignored).
"""

from __future__ import annotations

import http.client
import json
import re
import shutil
import signal
import socket
import time
from dataclasses import dataclass
from html.parser import HTMLParser
from typing import TYPE_CHECKING, Any

import pytest

from rosl.introspection import live_view
from rosl.introspection.graph_view import Channel, GraphModel
from tests.conftest import REPO, Processes, free_port, lock_domain
from tests.introspection.conftest import run_chromium
from tests.launch.support import Output, one_error_line

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from tests.introspection.conftest import Browser

pytestmark = [pytest.mark.slow, pytest.mark.timeout(300)]
BROWSER_TIMEOUT = pytest.mark.timeout(1500)  # room for apt-get installing chromium first
ARTIFACTS = REPO / "tests" / "artifacts" / "live_view"
URL_LINE = r"^live view at (http://127\.0\.0\.1:(\d+)/) \(Ctrl-C to stop\)$"
DRIVE = ("topic", "pub", "/cmd_vel", "geometry_msgs/msg/Twist",
         "{linear: {x: 0.2}, angular: {z: 0.3}}", "-r", "10")  # fmt: skip
SCAN_RGB = (0x00, 0xBC, 0xD4)  # the scan points' colour, as the PNG draws them
FOOTPRINT_RGB = (0xFF, 0xD5, 0x4F)


@dataclass
class Live:
    url: str
    port: int
    folder: Path
    viz: Output


def start_server(group: Processes, env: dict[str, str], *args: str) -> tuple[Output, str, int]:
    """``rosl viz --serve ARGS``, waiting (bounded) for the line naming its URL."""
    viz = Output(group.rosl("viz", "--serve", *args, env=env))
    assert viz.wait_for(URL_LINE, timeout=60.0), viz.both()
    match = viz.matching(URL_LINE)[0]
    return viz, match[1], int(match[2])


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Live]:
    """The simulator, a driver on /cmd_vel and the served page, on a domain of their own."""
    folder = tmp_path_factory.mktemp("live_view")
    domain, lock = lock_domain()
    env = {"ROSL_DOMAIN_ID": str(domain), "NO_COLOR": "1", "ROSL_LOG_DIR": str(folder / "log")}
    group = Processes()
    try:
        sim = Output(group.rosl("sim", "turtlebot3_world", "--headless", env=env, cwd=folder))
        assert sim.wait_for(r"turtlebot3_world is up", stream="err", timeout=60.0), sim.both()
        Output(group.rosl(*DRIVE, env=env, cwd=folder))
        viz, url, port = start_server(group, env, "--port", str(free_port()))
        yield Live(url, port, folder, viz)
    finally:
        group.close()
        lock.close()


# --- reading the page over HTTP -----------------------------------------------------------------


def get(port: int, path: str) -> tuple[int, str, bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=15)
    try:
        connection.request("GET", path)
        response = connection.getresponse()
        return response.status, response.getheader("Content-Type", ""), response.read()
    finally:
        connection.close()


def read_events(port: int, until: Any, timeout: float = 30.0) -> list[tuple[float, str, Any]]:
    """(arrival, event, decoded data) from /events until ``until(events)`` is true (bounded)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    events: list[tuple[float, str, Any]] = []
    try:
        connection.request("GET", "/events")
        response = connection.getresponse()
        assert response.status == 200
        assert response.getheader("Content-Type") == "text/event-stream"
        deadline = time.monotonic() + timeout
        name, data = "message", ""
        while time.monotonic() < deadline and not until(events):
            line = response.fp.readline().decode()
            assert line, "the event stream ended"
            if line.startswith("event:"):
                name = line[6:].strip()
            elif line.startswith("data:"):
                data += line[5:].strip()
            elif line == "\n" and data:
                events.append((time.monotonic(), name, json.loads(data)))
                name, data = "message", ""
    finally:
        connection.close()
    return events


def states(events: list[tuple[float, str, Any]]) -> list[dict[str, Any]]:
    return [data for _, name, data in events if name == "state"]


def pose(state: dict[str, Any]) -> tuple[float, float, float] | None:
    robots = state.get("robots") or []
    return (robots[0]["x"], robots[0]["y"], robots[0]["yaw"]) if robots else None


def complete(events: list[tuple[float, str, Any]]) -> list[dict[str, Any]]:
    """The states with everything in them: the world, a scan, the robot and its footprint."""
    return [
        s
        for s in states(events)
        if s["error"] is None and s["scan"] and s["circles"] and s["robots"] and s["footprints"]
    ]


def test_the_event_stream_sends_the_world_the_moving_robot_and_the_graph(live: Live) -> None:
    events = read_events(
        live.port,
        lambda e: len({pose(s) for s in complete(e)}) > 1 and any(n == "graph" for _, n, _ in e),
        timeout=60.0,
    )

    drawn = complete(events)
    assert drawn, events[:3]
    first = drawn[0]
    assert first["frame"] == "odom"
    assert first["note"] is None
    assert len(first["scan"]) > 50  # the last LaserScan's points
    assert len(first["circles"]) == 9  # turtlebot3_world's pillars, from /world_markers
    assert len(first["segments"]) > 30  # its walls
    assert [r["topic"] for r in first["robots"]] == ["/odom"]
    assert len(first["footprints"]) == 1  # the robot's, from /robot_description
    names = {f["name"] for f in first["frames"]}
    assert {"odom", "/odom pose", "base_scan"} <= names
    assert len({pose(s) for s in drawn}) > 1, "the pose changes while the robot drives"
    graph = next(data for _, name, data in events if name == "graph")
    assert {"name": "/sim", "count": 1} in graph["nodes"]
    scan = next(c for c in graph["channels"] if c["name"] == "/scan")
    assert scan["sources"] == ["/sim"]
    assert scan["types"] == ["sensor_msgs/msg/LaserScan"]


def test_snapshots_are_small_and_at_most_five_a_second(live: Live) -> None:
    started = time.monotonic()
    events = read_events(live.port, lambda e: len(states(e)) >= 12, timeout=60.0)
    elapsed = time.monotonic() - started

    sent = states(events)
    assert len(sent) >= 12
    # the first comes at once on connecting; after it, one per 0.2 s at most
    assert len(sent) - 1 <= elapsed / live_view.STATE_PERIOD_S + 1
    for state in sent:
        assert len(json.dumps(state)) < 64_000
        assert all(len(p["points"]) <= live_view.PATH_POINTS for p in state["paths"])


@pytest.mark.parametrize(
    ("path", "kind"),
    [
        ("/", "text/html; charset=utf-8"),
        ("/index.html", "text/html; charset=utf-8"),
        ("/viz.js", "text/javascript; charset=utf-8"),
        ("/viz.css", "text/css; charset=utf-8"),
        ("/state.json", "application/json"),
        ("/graph.json", "application/json"),
    ],
)
def test_the_page_files_and_snapshots_are_served_with_their_content_types(
    live: Live, path: str, kind: str
) -> None:
    code, content_type, body = get(live.port, path)

    assert code == 200
    assert content_type == kind
    assert body
    if kind == "application/json":
        assert isinstance(json.loads(body), dict)
    else:  # nothing is fetched from the internet: the only URL is SVG's namespace
        urls = set(re.findall(rb"https?://[^\s\"')]+", body))
        assert urls <= {b"http://www.w3.org/2000/svg"}


def test_the_page_comes_with_the_latest_snapshot_so_it_draws_at_once(live: Live) -> None:
    _, _, body = get(live.port, "/")

    match = re.search(rb'<script id="initial" type="application/json">(.*?)</script>', body)
    assert match is not None
    initial = json.loads(match[1])
    assert initial["state"]["frame"] == "odom"
    assert any(n["name"] == "/sim" for n in initial["graph"]["nodes"])


@pytest.mark.parametrize("path", ["/nope", "/../setup.cfg", "/rosl/web/viz.js", "/events/x"])
def test_an_unknown_path_is_404(live: Live, path: str) -> None:
    code, _, body = get(live.port, path)

    assert code == 404
    assert b"no such page" in body


# --- in a real browser ----------------------------------------------------------------------------

SCAN_POINTS = "document.querySelectorAll('#world #scan .scan-point').length"
FOOTPRINTS = "document.querySelectorAll('#world #footprints .footprint').length"
ROBOT = "(() => { const r = document.getElementById('robot');"
ROBOT += " return r ? [r.dataset.x, r.dataset.y, r.dataset.yaw].join(' ') : null; })()"


def keep(path: Path) -> Path:
    """Copy a screenshot to tests/artifacts/live_view/ and say where both copies are."""
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    kept = shutil.copy2(path, ARTIFACTS / path.name)
    print(f"screenshot: {path} (kept as {kept})")
    return path


def check_picture(path: Path) -> None:
    """A real picture: not one colour, with scan points and the robot's footprint in it."""
    from PIL import Image

    with Image.open(path) as image:
        assert image.format == "PNG"
        rgb = image.convert("RGB")
        colours = rgb.getcolors(maxcolors=1 << 20)
    assert colours is not None
    assert len(colours) > 2, f"{path} is a blank page"

    def near(target: tuple[int, int, int]) -> int:
        return sum(
            n for n, c in colours if max(abs(a - b) for a, b in zip(c, target, strict=True)) < 24
        )

    assert near(SCAN_RGB) > 20, f"{path}: no scan points"
    assert near(FOOTPRINT_RGB) > 20, f"{path}: no robot footprint"


@BROWSER_TIMEOUT
def test_a_browser_draws_the_scan_and_the_robot_moving_live(
    live: Live, browser: Browser, tmp_path: Path
) -> None:
    browser.open(live.url)

    ready = f"{SCAN_POINTS} > 0 && {FOOTPRINTS} === 1"
    assert browser.wait_for(ready), browser.evaluate("document.body.outerHTML")
    first = browser.wait_for(ROBOT)
    assert first is not None
    shot = keep(browser.screenshot(tmp_path / "live-world-1.png"))
    # the same page, not reloaded: updated over the event stream
    later = browser.wait_for(f"({ROBOT}) !== {json.dumps(first)} && ({ROBOT})")
    assert later, f"the robot's pose stayed at {first}"
    assert browser.evaluate(SCAN_POINTS) > 0
    assert browser.evaluate("document.getElementById('world').dataset.frame") == "odom"
    assert browser.evaluate("document.getElementById('status').dataset.state") == "live"
    assert browser.evaluate("document.querySelectorAll('#paths .path').length") == 1
    assert browser.evaluate(FOOTPRINTS) == 1
    shot_later = keep(browser.screenshot(tmp_path / "live-world-2.png"))
    for path in (shot, shot_later):
        check_picture(path)
    assert browser.exceptions == []


@BROWSER_TIMEOUT
def test_the_graph_tab_draws_the_nodes_and_topics(live: Live, browser: Browser, tmp_path: Path):
    browser.open(live.url + "#graph")

    assert browser.wait_for("document.querySelector('.graph-node[data-name=\"/sim\"]') !== null")
    topics = browser.evaluate(
        "[...document.querySelectorAll('.graph-topic')].map(g => g.dataset.name)"
    )
    assert {"/scan", "/odom", "/cmd_vel", "/tf"} <= set(topics)
    edges = browser.evaluate(
        "[...document.querySelectorAll('.graph-edge')].map(e => e.dataset.from + '>' + e.dataset.to)"
    )
    assert "n:/sim>t:/scan" in edges  # publisher -> topic
    assert "t:/cmd_vel>n:/sim" in edges  # topic -> subscriber
    assert browser.evaluate("document.getElementById('panel-world').hidden") is True
    keep(browser.screenshot(tmp_path / "live-graph.png"))
    assert browser.exceptions == []


class _Dom(HTMLParser):
    """The scan points and the robot's data- attributes in a dumped DOM."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.scan_points = 0
        self.footprints = 0
        self.robot: tuple[str, str, str] | None = None
        self.feed(text)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        if tag == "circle" and found.get("class") == "scan-point":
            self.scan_points += 1
        if tag == "polygon" and found.get("class") == "footprint":
            self.footprints += 1
        if found.get("id") == "robot":
            self.robot = (found["data-x"] or "", found["data-y"] or "", found["data-yaw"] or "")


@BROWSER_TIMEOUT
def test_dumped_dom_and_screenshots_taken_seconds_apart_show_the_robot_moving(
    live: Live, chromium: Path, tmp_path: Path
) -> None:
    def dump(number: int) -> _Dom:
        return _Dom(run_chromium(chromium, tmp_path / f"dump-{number}", ["--dump-dom", live.url]))

    deadline = time.monotonic() + 30.0
    first, number = dump(0), 0
    while not (first.scan_points and first.footprints) and time.monotonic() < deadline:
        time.sleep(0.5)  # only when run alone: the first messages are still on their way
        number += 1
        first = dump(number)
    assert first.scan_points > 0
    assert first.footprints == 1
    assert first.robot is not None
    later, number = dump(number + 1), number + 1
    deadline = time.monotonic() + 30.0
    while later.robot == first.robot and time.monotonic() < deadline:
        time.sleep(1.0)
        number += 1
        later = dump(number)
    assert later.robot != first.robot, f"the pose stayed at {first.robot}"
    assert later.scan_points > 0
    shots = []
    for number in (1, 2):
        path = tmp_path / f"screenshot-{number}.png"
        run_chromium(
            chromium, tmp_path / f"shot-{number}",
            ["--window-size=1000,900", f"--screenshot={path}", live.url],
        )  # fmt: skip
        shots.append(keep(path))
        time.sleep(2.0)
    for path in shots:
        check_picture(path)


DOLLY_NOTE = (
    "fixed frame: odom_demo (there is no 'odom' frame; odom_demo is the frame of /dolly/odom)"
)


def wait_state(port: int, predicate: Any, timeout: float = 30.0) -> dict[str, Any]:
    """/state.json polled until ``predicate(state)`` (bounded); the last state read."""
    deadline = time.monotonic() + timeout
    while True:
        state = json.loads(get(port, "/state.json")[2])
        if predicate(state) or time.monotonic() > deadline:
            return state
        time.sleep(0.2)


@BROWSER_TIMEOUT
def test_dollys_world_is_drawn_in_its_odometry_frame_and_the_page_says_why(
    processes: Processes, chromium: Path, tmp_path: Path
) -> None:
    sim = Output(processes.rosl("sim", "dolly_field", "--headless", cwd=tmp_path))
    assert sim.wait_for(r"dolly_field is up", stream="err", timeout=60.0), sim.both()
    _, url, port = start_server(processes, {}, "--port", "0")
    _, _, chassis_port = start_server(processes, {}, "--port", "0", "--fixed-frame", "chassis")

    state = wait_state(port, lambda s: s["error"] is None and s["scan"] and s["robots"])
    assert state["frame"] == "odom_demo"
    assert state["note"] == DOLLY_NOTE
    assert [r["topic"] for r in state["robots"]] == ["/dolly/odom"]
    dom = run_chromium(chromium, tmp_path / "dolly", ["--dump-dom", url])
    assert f'<p id="note">{DOLLY_NOTE}</p>' in dom.replace("&#39;", "'")
    assert "live (fixed frame: odom_demo)</text>" in dom
    asked = wait_state(chassis_port, lambda s: s["error"] is None and s["scan"] and s["robots"])
    assert asked["frame"] == "chassis"
    assert asked["note"] is None


def test_a_simulator_started_after_the_server_is_drawn(processes: Processes, tmp_path: Path):
    _, _, port = start_server(processes, {}, "--port", "0")
    assert wait_state(port, lambda s: s is not None)["error"].startswith("nothing to draw")
    sim = Output(processes.rosl("sim", "turtlebot3_world", "--headless", cwd=tmp_path))
    assert sim.wait_for(r"turtlebot3_world is up", stream="err", timeout=60.0), sim.both()

    state = wait_state(
        port, lambda s: s["error"] is None and s["scan"] and s["circles"] and s["robots"]
    )
    assert state["error"] is None
    assert len(state["circles"]) == 9
    assert [r["topic"] for r in state["robots"]] == ["/odom"]


# --- bad inputs, and stopping ---------------------------------------------------------------------


def test_serve_with_a_bag_is_a_usage_error(processes: Processes, tmp_path: Path) -> None:
    viz = Output(processes.rosl("viz", "--serve", str(tmp_path / "run1")))

    assert viz.finish(60.0) == 2
    err = viz.text("err")
    assert "Traceback" not in err
    errors = [line for line in err.splitlines() if line.startswith("Error:")]
    assert errors == [f"Error: --serve shows the live bus: give no BAG ({tmp_path / 'run1'}), "
                      "or drop --serve"]  # fmt: skip


def test_a_port_in_use_is_one_line(processes: Processes) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        viz = Output(processes.rosl("viz", "--serve", "--port", str(port)))
        code = viz.finish(60.0)

    assert code == 1
    assert viz.text("out") == ""
    assert one_error_line(viz.text("err")) == (
        f"cannot serve on 127.0.0.1:{port}: the port is in use (pick another with --port)"
    )


def test_an_address_of_another_machine_is_one_line(processes: Processes) -> None:
    # 192.0.2.1 is TEST-NET-1: never an address of this machine; binding sends nothing
    viz = Output(processes.rosl("viz", "--serve", "--address", "192.0.2.1", "--port", "0"))

    assert viz.finish(60.0) == 1
    assert one_error_line(viz.text("err")) == (
        "cannot serve on 192.0.2.1:0: '192.0.2.1' is not an address of this machine"
    )


def test_ctrl_c_stops_the_server_quietly_with_a_stream_open(processes: Processes) -> None:
    viz, _, port = start_server(processes, {}, "--port", "0")  # nothing on this test's domain
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=15)
    connection.request("GET", "/events")
    stream = connection.getresponse()
    assert stream.status == 200
    code, _, body = get(port, "/state.json")
    assert code == 200
    assert json.loads(body)["error"].startswith("nothing to draw")

    assert viz.interrupt(signal.SIGINT, timeout=30.0) == 130
    connection.close()
    assert viz.text("err") == ""
    with pytest.raises(ConnectionRefusedError), socket.create_connection(("127.0.0.1", port), 5):
        pass


# --- the library's pieces ---------------------------------------------------------------------------


def test_decimate_keeps_the_ends_and_at_most_the_limit() -> None:
    points = [(float(i), 0.0) for i in range(1000)]

    kept = live_view.decimate(points, 300)

    assert len(kept) == 300
    assert kept[0] == points[0]
    assert kept[-1] == points[-1]
    assert kept == sorted(kept)
    assert live_view.decimate(points[:10], 300) == points[:10]


def test_the_snapshot_in_the_page_cannot_end_its_script_element() -> None:
    hub = live_view.Hub()
    hub.publish("state", live_view.encode({"frame": "</script><b>odom"}))

    script = live_view.initial_script(hub)

    assert script.count(b"</script>") == 1
    assert script.endswith(b"</script>")
    inner = script[len(b'<script id="initial" type="application/json">') : -len(b"</script>")]
    assert json.loads(inner) == {"state": {"frame": "</script><b>odom"}, "graph": None}


def test_the_hub_sends_each_new_payload_once_and_unchanged_ones_never() -> None:
    hub = live_view.Hub()
    hub.publish("state", b"1")
    seen: dict[str, int] = {}

    news = hub.wait(seen, timeout=0.0)
    assert news is not None
    assert [(k, p) for k, _, p in news] == [("state", b"1")]
    seen.update({k: v for k, v, _ in news})
    hub.publish("state", b"1")
    assert hub.wait(seen, timeout=0.0) == []
    hub.close()
    assert hub.wait(seen, timeout=0.0) is None


def test_the_graph_json_has_what_rosl_graph_draws() -> None:
    model = GraphModel(
        {"/sim": 1, "/talker": 2},
        (Channel("/scan", "topic", ("sensor_msgs/msg/LaserScan",), ("/sim",), (), ("dead sink",)),),
    )

    assert live_view.graph_json(model) == {
        "nodes": [{"name": "/sim", "count": 1}, {"name": "/talker", "count": 2}],
        "channels": [
            {"name": "/scan", "kind": "topic", "types": ["sensor_msgs/msg/LaserScan"],
             "sources": ["/sim"], "sinks": [], "marks": ["dead sink"]},
        ],
    }  # fmt: skip


def _cylinder_world(count: int) -> Any:
    from rosl.idl.registry import get_message_class

    marker_array = get_message_class("visualization_msgs/msg/MarkerArray")
    marker = get_message_class("visualization_msgs/msg/Marker")
    markers = []
    for i in range(count):
        m = marker(type=3, id=i)
        m.header.frame_id = "odom"
        m.pose.position.x = float(i)
        m.scale.x = 0.3
        markers.append(m)
    return marker_array(markers=markers)


def test_a_topics_new_world_replaces_the_one_it_sent_before() -> None:
    from rosl.introspection.viz import MARKERS, VizBuilder

    builder = VizBuilder()
    feed = live_view.Feed(None, builder)  # type: ignore[arg-type] - take() needs no node

    feed.take("/world_markers", MARKERS, _cylinder_world(9))
    feed.take("/other_markers", MARKERS, _cylinder_world(2))
    feed.take("/world_markers", MARKERS, _cylinder_world(9))  # the simulator restarted

    assert len(builder.circles) == 11


def test_a_long_odometry_path_is_thinned_not_grown_without_bound() -> None:
    from rosl.idl.registry import get_message_class
    from rosl.introspection.viz import ODOMETRY, VizBuilder

    odometry = get_message_class(ODOMETRY)
    builder = VizBuilder()
    feed = live_view.Feed(None, builder)  # type: ignore[arg-type]
    for i in range(3 * live_view.KEPT_POSES):
        message = odometry()
        message.header.frame_id = "odom"
        message.pose.pose.position.x = float(i)
        feed.take("/odom", ODOMETRY, message)

    poses = builder.paths["/odom"]
    assert len(poses) <= live_view.KEPT_POSES
    assert poses[0][1] == 0.0
    assert [x for _, x, _ in poses] == sorted(x for _, x, _ in poses)
    assert builder.last_pose["/odom"][1].translation[0] == 3 * live_view.KEPT_POSES - 1


# --- the browser's installation (tests/introspection/conftest.py) ---------------------------------


@pytest.fixture
def no_chromium(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[list[str]]:
    """chromium absent, as root with apt-get; the apt-get calls made are recorded."""
    from tests import debian
    from tests.introspection import conftest

    calls: list[list[str]] = []
    monkeypatch.setattr(conftest, "CHROMIUM", tmp_path / "no-chromium")
    monkeypatch.setattr(debian.os, "geteuid", lambda: 0)
    monkeypatch.setattr(debian.shutil, "which", lambda name: f"/usr/bin/{name}")
    monkeypatch.setattr(debian, "APT_LISTS", tmp_path)  # no package lists yet

    def apt(args: list[str], timeout: float) -> object:
        raise AssertionError(f"apt-get {' '.join(args)} would run")

    monkeypatch.setattr(debian, "_apt", apt)  # a test that expects apt-get replaces this
    return calls


def test_chromium_cannot_be_installed_without_root(
    no_chromium: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    from tests import debian
    from tests.introspection import conftest

    monkeypatch.setattr(debian.os, "geteuid", lambda: 1000)

    reason = conftest.install_chromium()

    assert reason is not None
    assert reason.endswith("is missing and cannot be installed: apt-get needs root")


def test_chromium_cannot_be_installed_without_apt_get(
    no_chromium: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    from tests import debian
    from tests.introspection import conftest

    monkeypatch.setattr(debian.shutil, "which", lambda name: None)

    assert conftest.install_chromium() == (
        f"{conftest.CHROMIUM} is missing and cannot be installed: there is no apt-get here"
    )


def test_a_failed_install_updates_once_retries_and_says_why(
    no_chromium: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    import subprocess

    from tests import debian
    from tests.introspection import conftest

    def apt(args: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
        no_chromium.append(args)
        code = 0 if args == ["update"] else 100
        return subprocess.CompletedProcess(args, code, "", "E: Unable to locate package chromium")

    monkeypatch.setattr(debian, "_apt", apt)

    reason = conftest.install_chromium()

    assert reason == "apt-get install chromium failed: E: Unable to locate package chromium"
    assert no_chromium == [
        ["update"],
        ["install", "-y", "chromium"],
        ["update"],
        ["install", "-y", "chromium"],
    ]


def test_an_install_that_hangs_is_bounded(
    no_chromium: list[list[str]], monkeypatch: pytest.MonkeyPatch
) -> None:
    import subprocess

    from tests import debian
    from tests.introspection import conftest

    def apt(args: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
        raise subprocess.TimeoutExpired(["apt-get", *args], timeout)

    monkeypatch.setattr(debian, "_apt", apt)

    assert conftest.install_chromium() == (
        f"apt-get did not finish within {debian.APT_UPDATE_S} s: apt-get update"
    )
