"""rosl's bags as outside tools read them: rosbags, mcap + mcap-ros2-support, Foxglove's decoder.

One bag is recorded for the module by real processes on a domain of its own: a node started
*before* the recorder holds a transient-local /tf_static (published once, before anyone listens),
a /silent publisher that never publishes and an /add_two_ints server; then ``rosl bag record -a
--include-services`` starts, a talker sends PoseStamped, LaserScan, String, JointState and
TFMessage messages and a client makes three calls (so service events are recorded). What was
sent is kept as plain field values and compared with what each reader decodes:

- ``rosbags.highlevel.AnyReader`` and ``rosbags.rosbag2.Reader`` (types from the bag itself);
- ``mcap`` with ``mcap_ros2.decoder.DecoderFactory`` (mcap-ros2-support), every topic but the
  service events (it decodes none, rosbag2's own included);
- Foxglove's and Lichtblick's stack — ``@mcap/core``'s indexed reader, ``@foxglove/rosmsg`` /
  ``@foxglove/ros2idl-parser`` and ``@foxglove/rosmsg2-serialization`` — through
  ``foxglove_decode.mjs`` under node (npm packages installed by a session fixture into
  ``~/.cache/rosl-tests/foxglove-npm``), on the bag as recorded and on a zstd-compressed copy;
- foxglove/mcap's validator (``mcap doctor``), its release binary downloaded by the test setup
  where it is missing.

``rosl bag filter``, ``rosl bag convert --compression-format zstd`` and ``rosl bag reindex`` (of
a copy cut after its last chunk, without metadata.yaml) are read back with AnyReader, and every
bag is checked for what rosbag2's MCAP storage writes: a channel and schema for every topic of
metadata.yaml (also one with no messages), ``offered_qos_profiles`` and ``topic_type_hash`` in
each channel's metadata (the hash equal to rosbags' RIHS01 of the schema) and a ``rosbag2``
metadata record holding ``serialized_metadata``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import functools
import json
import os
import shutil
import signal
import subprocess
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
import yaml

from tests.bag_record import support
from tests.bag_record.conftest import CLIENT, DomainProcesses
from tests.conftest import lock_domain
from tests.debian import install

if TYPE_CHECKING:
    from collections.abc import Iterator

pytestmark = pytest.mark.timeout(300)  # room for the first npm install

HERE = Path(__file__).resolve().parent
NODE_SCRIPT = HERE / "foxglove_decode.mjs"
NPM_CACHE = Path.home() / ".cache" / "rosl-tests" / "foxglove-npm"
NPM_PACKAGES = {  # what Foxglove and Lichtblick read MCAP + ROS 2 CDR with; exact versions
    "@mcap/core": "2.2.2",
    "@foxglove/rosmsg": "5.0.5",
    "@foxglove/ros2idl-parser": "0.3.5",
    "@foxglove/rosmsg2-serialization": "3.1.0",
    "@foxglove/wasm-zstd": "1.0.1",
    "@foxglove/wasm-lz4": "1.0.2",
}
MCAP_CLI_CACHE = Path.home() / ".cache" / "rosl-tests" / "bin" / "mcap"
MCAP_CLI_RELEASE = "releases/mcap-cli/v0.0.58"  # foxglove/mcap's Go CLI, a GitHub release

EVENT_TOPIC = "/add_two_ints/_service_event"
EVENT_TYPE = "example_interfaces/srv/AddTwoInts_Event"
REQUEST_SENT, RESPONSE_SENT = 0, 2
CALLS = [[2, 3], [-10, 4], [2**40, -7]]


# --- what is sent ------------------------------------------------------------------------------


def header(sec: int, nanosec: int, frame_id: str) -> dict[str, Any]:
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id}


def transform(sec: int, parent: str, child: str, x: float, w: float) -> dict[str, Any]:
    return {
        "header": header(sec, 125_000_000, parent),
        "child_frame_id": child,
        "transform": {
            "translation": {"x": x, "y": -0.5, "z": 0.25},
            "rotation": {"x": 0.0, "y": 0.0, "z": (1.0 - w * w) ** 0.5, "w": w},
        },
    }


TF_STATIC = {"transforms": [transform(1_700_000_000, "base_link", "laser", 0.125, 1.0)]}
# float32 fields hold values a float32 holds exactly, so every reader's float equals the sent one
PUBLISHERS: list[dict[str, Any]] = [
    {"topic": "/pose", "type": "geometry_msgs/msg/PoseStamped"},
    {"topic": "/scan", "type": "sensor_msgs/msg/LaserScan"},
    {"topic": "/chatter", "type": "std_msgs/msg/String"},
    {"topic": "/joint_states", "type": "sensor_msgs/msg/JointState"},
    {"topic": "/tf", "type": "tf2_msgs/msg/TFMessage"},
]
SENT: dict[str, list[dict[str, Any]]] = {
    "/pose": [
        {
            "header": header(1_700_000_000 + i, 250_000_000 * i, "map"),
            "pose": {
                "position": {"x": 1.5 * i, "y": -2.25, "z": 1e-9},
                "orientation": {
                    "x": 0.0,
                    "y": 0.0,
                    "z": 0.7071067811865476,
                    "w": 0.7071067811865476,
                },
            },
        }
        for i in range(3)
    ],
    "/scan": [
        {
            "header": header(1_700_000_100 + i, 7 * i, "laser"),
            "angle_min": -1.5,
            "angle_max": 1.5,
            "angle_increment": 0.75,
            "time_increment": 0.0,
            "scan_time": 0.125,
            "range_min": 0.0625,
            "range_max": 12.0,
            "ranges": [1.0, 2.5, 0.0, 3.75 + i, 11.5],
            "intensities": [100.0, 0.5, 7.0, 1.0, 2.0] if i else [],
        }
        for i in range(3)
    ],
    "/chatter": [{"data": text} for text in ("hello ünïcode ✓", "", "two\nlines")],
    "/joint_states": [
        {
            "header": header(1_700_000_200, i, f"base_{i}"),
            "name": ["shoulder", "elbow", "wrist"][: i + 1],
            "position": [0.1 * k - 1.0 for k in range(i + 1)],
            "velocity": [],
            "effort": [-1.5e3] * i,
        }
        for i in range(3)
    ],
    "/tf": [
        {
            "transforms": [
                transform(1_700_000_300 + i, "odom", "base_link", 0.5 * i, 0.6),
                transform(1_700_000_300 + i, "map", "odom", -0.25, 0.8),
            ]
        }
        for i in range(2)
    ],
}
SENT_BY_TALKER = {topic: list(fields) for topic, fields in SENT.items()}
SENT["/tf_static"] = [TF_STATIC]
TYPES = {p["topic"]: p["type"] for p in PUBLISHERS} | {
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/silent": "std_msgs/msg/Float64",
    EVENT_TOPIC: EVENT_TYPE,
}

# started before the recorder: a latched /tf_static, a /silent that never publishes, the server
BEFORE = r"""
import json, sys, time
import rosl
from example_interfaces.srv import AddTwoInts
from rosl.idl import registry
from rosl.idl.messages import from_dict
from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

rosl.init([])
node = rosl.Node("outside_readers_before")
latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     reliability=ReliabilityPolicy.RELIABLE)
TFMessage = registry.get_message_class("tf2_msgs/msg/TFMessage")
tf_static = node.create_publisher(TFMessage, "/tf_static", latched)
silent = node.create_publisher(registry.get_message_class("std_msgs/msg/Float64"), "/silent", 10)


def add(request, response):
    response.sum = request.a + request.b
    return response


node.create_service(AddTwoInts, "/add_two_ints", add)
tf_static.publish(from_dict(TFMessage, json.loads(sys.argv[1])))
print("READY", flush=True)
deadline = time.monotonic() + 30.0
while time.monotonic() < deadline and (
    tf_static.get_subscription_count() < 1 or silent.get_subscription_count() < 1
):
    rosl.spin_once(node, timeout_sec=0.02)
print("HEARD" if time.monotonic() < deadline else "NOBODY", flush=True)
try:
    rosl.spin(node)
except KeyboardInterrupt:
    pass
"""


@dataclasses.dataclass
class Recording:
    folder: Path
    calls: list[dict[str, int]]
    root: Path


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Recording]:
    root = tmp_path_factory.mktemp("outside_readers")
    folder = root / "recorded"
    domain, lock = lock_domain()
    group = DomainProcesses(domain)
    try:
        before = support.Child(group.python(BEFORE, json.dumps(TF_STATIC), cwd=root))
        assert before.wait_for("^READY", timeout=30), before.both()
        recorder = support.start_recorder(
            group, "-a", "--include-services", "-o", str(folder), cwd=root
        )
        assert before.wait_for("^HEARD", timeout=30), before.both()
        support.run_publisher(
            group,
            {"node": "outside_readers_talker", "publishers": PUBLISHERS, "period": 0.01,
             "messages": [(PUBLISHERS.index(p), fields) for p in PUBLISHERS
                          for fields in SENT_BY_TALKER[p["topic"]]]},
            cwd=root,
        )  # fmt: skip
        client = support.Child(group.python(CLIENT, json.dumps(CALLS), cwd=root))
        assert client.finish(60) == 0, client.both()
        calls = [json.loads(line) for line in client.lines() if line.startswith("{")]
        assert [(c["a"], c["b"], c["sum"]) for c in calls] == [(a, b, a + b) for a, b in CALLS]
        assert before.signal(signal.SIGINT, timeout=15) is not None, before.both()
        support.stop_recorder(recorder)
        yield Recording(folder, calls, root)
    finally:
        group.close()
        lock.close()


def rosl_ok(*args: str, cwd: Path) -> None:
    result = support.rosl_run(*args, cwd=cwd, timeout=60)
    assert result.returncode == 0, (args, result.stdout, result.stderr)


FILTER_TOPICS = ["/pose", "/scan", "/tf_static", "/silent", EVENT_TOPIC]


@pytest.fixture(scope="module")
def filtered(recording: Recording) -> Path:
    out = recording.root / "filtered"
    rosl_ok("bag", "filter", str(recording.folder), str(out), "--topics", *FILTER_TOPICS,
            cwd=recording.root)  # fmt: skip
    return out


@pytest.fixture(scope="module")
def converted(recording: Recording) -> Path:
    out = recording.root / "converted_zstd"
    rosl_ok("bag", "convert", str(recording.folder), str(out), "--compression-format", "zstd",
            cwd=recording.root)  # fmt: skip
    return out


@pytest.fixture(scope="module")
def reindexed(recording: Recording) -> Path:
    """A copy cut where its summary began (DataEnd, summary, footer gone), no metadata.yaml."""
    out = recording.root / "reindexed"
    shutil.copytree(recording.folder, out)
    (out / "metadata.yaml").unlink()
    files = sorted(out.glob("*.mcap"))
    assert len(files) == 1, files
    footer = files[0].read_bytes()[-8 - 29 : -8]  # Footer: opcode, length, summary start, ...
    assert footer[0] == 0x02, "the recorded file does not end with a footer"
    summary_start = int.from_bytes(footer[9:17], "little")
    assert summary_start > 0, "the recorded file has no summary section"
    data_end_record = 1 + 8 + 4  # opcode, length, data section CRC
    with files[0].open("r+b") as handle:
        handle.seek(summary_start - data_end_record)
        assert handle.read(1) == b"\x0f", "no DataEnd record before the summary"
        handle.truncate(summary_start - data_end_record)
    rosl_ok("bag", "reindex", str(out), cwd=recording.root)
    return out


# rmw's durability numbers, as metadata versions before 9 write them
DURABILITY = {1: "transient_local", 2: "volatile"}
BAGS = ["recorded", "filtered", "converted", "reindexed"]


def bag(request: pytest.FixtureRequest, name: str) -> Path:
    if name == "recorded":
        return Path(request.getfixturevalue("recording").folder)
    return Path(request.getfixturevalue(name))


# --- comparing ---------------------------------------------------------------------------------


def normalized(value: Any) -> Any:
    """Any reader's decoded message as plain dicts, lists and numbers."""
    if isinstance(value, dict):
        return {str(k): normalized(v) for k, v in value.items()}
    if isinstance(value, (bytes, bytearray, memoryview)):
        return list(bytes(value))
    if isinstance(value, np.ndarray):
        return [normalized(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [normalized(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return normalized(support.plain(value))
    if hasattr(value, "__slots__") and not isinstance(value, (str, int, float)):
        return {name: normalized(getattr(value, name)) for name in value.__slots__}
    return value


def compare_with_sent(found: dict[str, list[Any]], calls: list[dict[str, int]]) -> None:
    """Each sent topic's messages, in order and field for field; the service events by call."""
    for topic, fields in SENT.items():
        assert found.get(topic) == fields, topic
    assert found.get("/silent", []) == []
    compare_events(found.get(EVENT_TOPIC, []), calls)


def compare_events(events: list[Any], calls: list[dict[str, int]]) -> None:
    """A REQUEST_SENT and a RESPONSE_SENT event per call, carrying its values, in call order."""
    requests = [e for e in events if e["info"]["event_type"] == REQUEST_SENT]
    responses = [e for e in events if e["info"]["event_type"] == RESPONSE_SENT]
    assert [(e["request"], e["response"]) for e in requests] == [
        ([{"a": c["a"], "b": c["b"]}], []) for c in calls
    ]
    assert [(e["request"], e["response"]) for e in responses] == [
        ([], [{"sum": c["sum"]}]) for c in calls
    ]
    assert len(events) == 2 * len(calls), events
    for event in events:
        assert len(event["info"]["client_gid"]) == 16, event
        assert any(event["info"]["client_gid"]), event
        assert event["info"]["sequence_number"] > 0, event


def by_topic(pairs: list[tuple[str, Any]]) -> dict[str, list[Any]]:
    found: dict[str, list[Any]] = {}
    for topic, message in pairs:
        found.setdefault(topic, []).append(normalized(message))
    return found


def anyreader_messages(folder: Path) -> dict[str, list[Any]]:
    from rosbags.highlevel import AnyReader

    with AnyReader([folder]) as reader:
        return by_topic([
            (connection.topic, reader.deserialize(raw, connection.msgtype))
            for connection, _, raw in reader.messages()
        ])  # fmt: skip


# --- rosbags -----------------------------------------------------------------------------------


def test_anyreader_decodes_every_message_as_it_was_sent(recording: Recording) -> None:
    compare_with_sent(anyreader_messages(recording.folder), recording.calls)


def test_rosbag2_reader_decodes_every_message_as_it_was_sent(recording: Recording) -> None:
    from rosbags.rosbag2 import Reader

    with Reader(recording.folder) as reader:
        connections = [c for c in reader.connections if c.msgdef.format.name != "NONE"]
        store = support.typestore_from([
            (c.msgtype, {"MSG": "ros2msg", "IDL": "ros2idl"}[c.msgdef.format.name], c.msgdef.data)
            for c in connections
        ])  # fmt: skip
        found = by_topic([
            (connection.topic, store.deserialize_cdr(raw, connection.msgtype))
            for connection, _, raw in reader.messages()
        ])  # fmt: skip
        assert {c.topic for c in reader.connections} >= set(TYPES), "a topic is missing"
    compare_with_sent(found, recording.calls)


# --- mcap + mcap-ros2-support ------------------------------------------------------------------


def is_service_event(schema_name: str) -> bool:
    return "/srv/" in schema_name and schema_name.endswith("_Event")


def mcap_ros2_decoded(folder: Path) -> list[tuple[str, Any]]:
    """(topic, message) decoded by mcap-ros2-support, on every channel but the service events."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    pairs = []
    for path in support.bag_files(folder):
        with path.open("rb") as handle:
            reader = make_reader(handle, decoder_factories=[DecoderFactory()])
            summary = reader.get_summary()
            assert summary is not None, path
            topics = [
                c.topic for c in summary.channels.values()
                if not is_service_event(summary.schemas[c.schema_id].name)
            ]  # fmt: skip
            for _, channel, _, decoded in reader.iter_decoded_messages(topics=topics):
                pairs.append((channel.topic, decoded))
    return pairs


def test_mcap_ros2_support_decodes_every_topic_message_as_it_was_sent(
    recording: Recording,
) -> None:
    """Every topic but the service events: mcap-ros2-support 0.6 decodes none of those, in any
    encoding (it has no ``ros2idl`` decoder, and its ``.msg`` parser refuses ``AddTwoInts_Event``
    as a message name), rosbag2's own bags included; rosbags and Foxglove read them (below)."""
    found = by_topic(mcap_ros2_decoded(recording.folder))
    for topic, fields in SENT.items():
        assert found.get(topic) == fields, topic
    assert "/silent" not in found


# --- Foxglove's decoder (node) -----------------------------------------------------------------


@pytest.fixture(scope="session")
def foxglove_modules() -> Path:
    """The npm prefix holding Foxglove's MCAP and ROS 2 packages (installed once, cached)."""
    reason = install(["nodejs", "npm"], ["node", "npm"])  # Debian's, where missing
    if reason is not None:
        pytest.skip(f"Foxglove's decoder runs under node: {reason}")
    npm = shutil.which("npm")
    assert npm is not None
    NPM_CACHE.mkdir(parents=True, exist_ok=True)
    manifest = {"name": "rosl-foxglove-readers", "private": True, "dependencies": NPM_PACKAGES}
    wanted = json.dumps(manifest, indent=2) + "\n"
    with (NPM_CACHE / ".lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        stamp = NPM_CACHE / ".installed"
        installed = stamp.is_file() and (NPM_CACHE / "node_modules").is_dir()
        if not installed or stamp.read_text() != wanted:
            (NPM_CACHE / "package.json").write_text(wanted)
            result = subprocess.run(
                [npm, "install", "--prefix", str(NPM_CACHE), "--no-audit", "--no-fund",
                 "--loglevel=error"],
                capture_output=True, text=True, timeout=240, check=False, cwd=NPM_CACHE,
            )  # fmt: skip
            assert result.returncode == 0, f"npm install failed:\n{result.stdout}{result.stderr}"
            stamp.write_text(wanted)
    return NPM_CACHE


@dataclasses.dataclass
class FoxgloveView:
    """What foxglove_decode.mjs printed for one file."""

    header: dict[str, Any]
    channels: list[dict[str, Any]]
    metadata: list[dict[str, Any]]
    messages: list[dict[str, Any]]
    errors: list[dict[str, Any]]


def foxglove_read(modules: Path, path: Path) -> FoxgloveView:
    node = shutil.which("node")
    assert node is not None
    result = subprocess.run(
        [node, str(NODE_SCRIPT), str(modules), str(path)],
        capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip
    assert result.returncode == 0, f"{path.name}: {result.stderr.strip()}"
    lines = [json.loads(line) for line in result.stdout.splitlines()]
    kinds: dict[str, list[dict[str, Any]]] = {}
    for line in lines:
        kinds.setdefault(line["kind"], []).append(line)
    return FoxgloveView(kinds["header"][0], kinds.get("channel", []), kinds.get("metadata", []),
                        kinds.get("message", []), kinds.get("error", []))  # fmt: skip


def check_foxglove_view(views: list[FoxgloveView], calls: list[dict[str, int]]) -> None:
    errors = [e for v in views for e in v.errors]
    assert errors == [], errors
    for view in views:
        assert view.header["profile"] == "ros2"
        assert all(c["messageEncoding"] == "cdr" for c in view.channels), view.channels
        assert not [m for m in view.messages if m["trailingBytes"]], "bytes left after a message"
        assert [m["name"] for m in view.metadata] == ["rosbag2"], view.metadata
    assert {c["topic"] for v in views for c in v.channels} >= set(TYPES)
    found = by_topic([(m["topic"], m["message"]) for v in views for m in v.messages])
    compare_with_sent(found, calls)


@pytest.mark.parametrize("name", ["recorded", "converted"])
def test_foxglove_decoder_reads_every_message_as_it_was_sent(
    request: pytest.FixtureRequest, foxglove_modules: Path, name: str
) -> None:
    folder = bag(request, name)
    views = [foxglove_read(foxglove_modules, path) for path in support.bag_files(folder)]
    check_foxglove_view(views, request.getfixturevalue("recording").calls)


def test_the_converted_bag_has_zstd_chunks_foxglove_decompressed(converted: Path) -> None:
    from mcap.reader import make_reader

    for path in support.bag_files(converted):
        with path.open("rb") as handle:
            summary = make_reader(handle).get_summary()
        assert summary is not None, path
        assert summary.chunk_indexes, path
        assert {c.compression for c in summary.chunk_indexes} == {"zstd"}, path


# --- foxglove/mcap's validator -----------------------------------------------------------------


def mcap_cli() -> str | None:
    """The Go ``mcap`` CLI: $ROSL_MCAP_CLI, the test cache, or an ``mcap`` on PATH that is it."""
    for candidate in (os.environ.get("ROSL_MCAP_CLI"), str(MCAP_CLI_CACHE), shutil.which("mcap")):
        if candidate and os.access(candidate, os.X_OK):
            with contextlib.suppress(OSError, subprocess.TimeoutExpired):
                probe = subprocess.run([candidate, "version"], capture_output=True, text=True,
                                       timeout=10, check=False)  # fmt: skip
                if probe.returncode == 0:
                    return candidate
    return None


def download_mcap_cli() -> str | None:
    """Fetch the pinned release binary into the test cache; why it cannot be, or None."""
    import platform
    import urllib.error
    import urllib.request

    build = {"x86_64": "linux-amd64", "aarch64": "linux-arm64"}.get(platform.machine())
    if build is None or platform.system() != "Linux":
        return f"no {MCAP_CLI_RELEASE} binary for {platform.system()} {platform.machine()}"
    url = f"https://github.com/foxglove/mcap/releases/download/{MCAP_CLI_RELEASE}/mcap-{build}"
    partial = MCAP_CLI_CACHE.with_suffix(f".{os.getpid()}.part")  # workers may race
    try:
        MCAP_CLI_CACHE.parent.mkdir(parents=True, exist_ok=True)
        with urllib.request.urlopen(url, timeout=30) as response:
            partial.write_bytes(response.read())
        partial.chmod(0o755)
        partial.replace(MCAP_CLI_CACHE)
    except (OSError, urllib.error.URLError) as err:
        partial.unlink(missing_ok=True)
        return f"{url} cannot be downloaded here ({err}), and there is no Go toolchain to build it"
    return None


@pytest.fixture(scope="session")
def mcap_doctor() -> str:
    """foxglove/mcap's CLI, downloaded into the test cache where missing (or a skip, saying why)."""
    cli = mcap_cli()
    if cli is None:
        reason = download_mcap_cli()
        cli = mcap_cli()
        if cli is None:
            pytest.skip(
                f"foxglove/mcap's `mcap` CLI is not here: {reason or 'the download does not run'}"
                f"; put the binary at {MCAP_CLI_CACHE} or name it in ROSL_MCAP_CLI"
            )
    return cli


@pytest.mark.parametrize("name", ["recorded", "converted"])
def test_mcap_doctor_finds_no_problem(
    request: pytest.FixtureRequest, mcap_doctor: str, name: str
) -> None:
    cli = mcap_doctor
    for path in support.bag_files(bag(request, name)):
        result = subprocess.run([cli, "doctor", str(path)], capture_output=True, text=True,
                                timeout=60, check=False)  # fmt: skip
        assert result.returncode == 0, f"{path.name}:\n{result.stdout}{result.stderr}"


# --- filter, convert, reindex ------------------------------------------------------------------


def test_filter_output_reads_back_with_anyreader(recording: Recording, filtered: Path) -> None:
    found = anyreader_messages(filtered)
    assert set(found) == set(FILTER_TOPICS) - {"/silent"}  # /silent has no messages
    for topic in ("/pose", "/scan", "/tf_static"):
        assert found[topic] == SENT[topic], topic
    assert len(found[EVENT_TOPIC]) == 2 * len(recording.calls)


def test_convert_output_reads_back_with_anyreader(recording: Recording, converted: Path) -> None:
    compare_with_sent(anyreader_messages(converted), recording.calls)


def test_reindexed_cut_copy_reads_back_with_anyreader(
    recording: Recording, reindexed: Path
) -> None:
    compare_with_sent(anyreader_messages(reindexed), recording.calls)


# --- what rosbag2's MCAP storage writes --------------------------------------------------------


@dataclasses.dataclass
class McapLook:
    """Channels, schemas and metadata records of one MCAP file, read with ``mcap``."""

    schemas: dict[int, Any]
    channels: dict[str, Any]
    metadata: list[Any]
    metadata_index_names: list[str]


def look(path: Path) -> McapLook:
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        reader = make_reader(handle)
        summary = reader.get_summary()
        assert summary is not None, f"{path.name} has no summary"
        records = list(reader.iter_metadata())
    return McapLook(
        summary.schemas,
        {c.topic: c for c in summary.channels.values()},
        records,
        [i.name for i in summary.metadata_indexes],
    )


@functools.cache
def rosbags_rihs01(name: str, encoding: str, text: str) -> str:
    """rosbags' RIHS01 hash of the type a schema defines.

    rosbags reads a ``.msg`` text as messages: a service's parts (``pkg/AddTwoInts_Request`` in a
    ``MSG:`` header, the root ``pkg/srv/AddTwoInts_Event``) come out as ``pkg/msg/...`` and
    ``pkg/srv/msg/...``; they get their ``pkg/srv/...`` names back before hashing, since the hash
    covers the names of the types referenced.
    """
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    if encoding != "ros2msg" or "/srv/" not in name:
        return support.rihs01(name, encoding, text)
    types = get_types_from_msg(text, name)
    renames = {}
    for key in types:
        short = key.rsplit("/", 1)[1]
        if short.endswith(("_Request", "_Response", "_Event")):
            renames[key] = f"{key.split('/', 1)[0]}/srv/{short}"

    def renamed(value: Any) -> Any:
        if isinstance(value, str):
            return renames.get(value, value)
        if isinstance(value, (list, tuple)):
            return type(value)(renamed(v) for v in value)
        return value

    store = get_typestore(Stores.EMPTY)
    store.register({renames.get(k, k): renamed(v) for k, v in types.items()})
    return str(store.hash_rihs01(name))


def listed_topics(folder: Path) -> dict[str, dict[str, Any]]:
    """metadata.yaml's topics by name (``offered_qos_profiles`` parsed where it is YAML text)."""
    found = {}
    for entry in support.metadata(folder)["topics_with_message_count"]:
        meta = dict(entry["topic_metadata"])
        if isinstance(meta.get("offered_qos_profiles"), str):  # as versions before 9 write it
            meta["offered_qos_profiles"] = yaml.safe_load(meta["offered_qos_profiles"])
        found[meta["name"]] = meta
    return found


@pytest.mark.parametrize("name", BAGS)
def test_every_topic_of_metadata_yaml_has_a_channel_and_its_schema(
    request: pytest.FixtureRequest, name: str
) -> None:
    folder = bag(request, name)
    listed = listed_topics(folder)
    if name != "filtered":
        assert set(listed) >= set(TYPES), sorted(listed)
    assert support.topic_counts(folder)["/silent"] == 0
    looks = [look(path) for path in support.bag_files(folder)]
    for topic, meta in listed.items():
        found = [(lk.channels[topic], lk.schemas) for lk in looks if topic in lk.channels]
        assert found, f"{topic} ({meta['type']}) has no MCAP channel"
        for channel, schemas in found:
            schema = schemas.get(channel.schema_id)
            assert schema is not None, f"{topic}: channel names schema {channel.schema_id}"
            assert schema.name == meta["type"], topic
            assert schema.encoding in ("ros2msg", "ros2idl"), topic
            assert schema.data, f"{topic}: empty schema"
            assert channel.message_encoding == "cdr", topic


@pytest.mark.parametrize("name", BAGS)
def test_every_channel_has_offered_qos_profiles_and_rosbags_topic_type_hash(
    request: pytest.FixtureRequest, name: str
) -> None:
    folder = bag(request, name)
    listed = listed_topics(folder)
    for path in support.bag_files(folder):
        current = look(path)
        for topic, channel in current.channels.items():
            schema = current.schemas[channel.schema_id]
            assert "offered_qos_profiles" in channel.metadata, (path.name, topic, channel.metadata)
            profiles = yaml.safe_load(channel.metadata["offered_qos_profiles"])
            assert profiles == listed[topic]["offered_qos_profiles"], topic
            assert "topic_type_hash" in channel.metadata, (path.name, topic, channel.metadata)
            expected = rosbags_rihs01(schema.name, schema.encoding, schema.data.decode())
            assert channel.metadata["topic_type_hash"] == expected, topic
            if support.metadata(folder)["version"] >= 8:  # metadata.yaml has the hash since 8
                assert listed[topic]["type_description_hash"] == expected, topic
    if "/tf_static" in listed:
        profiles = listed["/tf_static"]["offered_qos_profiles"]
        words = [DURABILITY.get(p["durability"], p["durability"]) for p in profiles]
        assert words == ["transient_local"], profiles


@pytest.mark.parametrize("name", BAGS)
def test_each_file_has_a_rosbag2_metadata_record_with_serialized_metadata(
    request: pytest.FixtureRequest, name: str
) -> None:
    folder = bag(request, name)
    listed = listed_topics(folder)
    for path in support.bag_files(folder):
        current = look(path)
        records = [r for r in current.metadata if r.name == "rosbag2"]
        assert len(records) == 1, (path.name, [(r.name, r.metadata) for r in current.metadata])
        assert "rosbag2" in current.metadata_index_names, "rosbag2 reads it through the index"
        text = records[0].metadata.get("serialized_metadata")
        assert text, (path.name, records[0].metadata)
        # what rosbag2's YAML::convert<BagMetadata> encodes: the mapping inside
        # rosbag2_bagfile_information, which it decodes again when opening the file alone
        meta = yaml.safe_load(text)
        assert isinstance(meta, dict), meta
        assert meta.get("storage_identifier") == "mcap", meta
        assert meta.get("version") == support.metadata(folder)["version"], meta
        topics = {e["topic_metadata"]["name"] for e in meta["topics_with_message_count"]}
        assert topics == set(listed), (sorted(topics), sorted(listed))
