"""Helpers for the recording tests: children read with deadlines, publishers, three readers.

A recording is made by real processes on the test's domain: ``rosl bag record`` as a child
(started, then waited for until it prints "Recording to"), publishers as Python children that
print, per message, the wall-clock time just before and just after ``publish``. The bag is then
read back with ``rosbags.highlevel.AnyReader``, ``rosbags.rosbag2.Reader`` (decoded with a
type store built from the bag's own definitions) and ``mcap.reader.make_reader`` (decoded the
same way), and compared with what the test serialises itself.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from tests.conftest import ChildOutput

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

RECORDING_TO = r"Recording to '"
STOP_TIMEOUT = 15.0

# --- children ----------------------------------------------------------------------------------


class Child(ChildOutput):
    """A child whose stdout/stderr are read with ``select`` and bounded waits."""

    @property
    def pid(self) -> int:
        return self.popen.pid

    def lines(self, stream: str = "out") -> list[str]:
        self.pump()
        return self.text[stream].splitlines()

    def wait_for(self, pattern: str, *, stream: str = "out", timeout: float = 30.0) -> bool:
        """Whether a line matching ``pattern`` appears within ``timeout``."""
        regex = re.compile(pattern, re.MULTILINE)
        deadline = time.monotonic() + timeout
        while True:
            if regex.search(self.text[stream]):
                return True
            remaining = deadline - time.monotonic()
            if remaining <= 0 or (not self._open and self.popen.poll() is not None):
                self.pump()
                return bool(regex.search(self.text[stream]))
            self._read(min(remaining, 0.05))

    def count(self, pattern: str, stream: str = "out") -> int:
        self.pump()
        return len(re.findall(pattern, self.text[stream], re.MULTILINE))

    def wait_count(
        self, pattern: str, count: int, *, stream: str = "out", timeout: float = 30.0
    ) -> bool:
        deadline = time.monotonic() + timeout
        while self.count(pattern, stream) < count:
            if time.monotonic() > deadline or (not self._open and self.popen.poll() is not None):
                return self.count(pattern, stream) >= count
            self._read(0.05)
        return True

    def finish(self, timeout: float = STOP_TIMEOUT) -> int | None:
        """Read to EOF and wait for the exit; the exit code, or None at the deadline."""
        deadline = time.monotonic() + timeout
        while self._open and time.monotonic() < deadline:
            self._read(min(deadline - time.monotonic(), 0.1))
        try:
            return self.popen.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            return None

    def signal(self, sig: int = signal.SIGINT, timeout: float = STOP_TIMEOUT) -> int | None:
        """Send ``sig`` (by pid) and wait for the exit."""
        if self.popen.poll() is None:
            self.popen.send_signal(sig)
        return self.finish(timeout)

    def both(self) -> str:
        self.pump()
        return f"--- stdout:\n{self.text['out']}\n--- stderr:\n{self.text['err']}"


def start_recorder(
    processes: Processes, *args: str, cwd: Path | None = None, timeout: float = 30.0
) -> Child:
    """``rosl bag record ARGS`` as a child, returned once it prints "Recording to"."""
    child = Child(processes.rosl("bag", "record", *args, cwd=cwd))
    if not child.wait_for(RECORDING_TO, stream="err", timeout=timeout):
        child.signal(signal.SIGKILL, timeout=5)
        raise AssertionError(f"the recorder never said 'Recording to'\n{child.both()}")
    return child


def stop_recorder(recorder: Child, sig: int = signal.SIGINT) -> str:
    """Stop the recorder with ``sig``; assert it exited by itself; return its stderr."""
    code = recorder.signal(sig)
    assert code is not None, f"the recorder did not exit after {sig!r}\n{recorder.both()}"
    assert code == 0, f"the recorder exited with {code}\n{recorder.both()}"
    return recorder.text["err"]


def one_line_error(result: subprocess.CompletedProcess[str]) -> str:
    """The one line a refused command printed (exit 1, no traceback)."""
    assert result.returncode == 1, (result.returncode, result.stdout, result.stderr)
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def rosl_run(
    *args: str,
    cwd: Path | None = None,
    env: dict[str, str] | None = None,
    timeout: float = 30.0,
) -> subprocess.CompletedProcess[str]:
    """Run ``rosl ARGS`` to the end (bounded) and return its result."""
    return subprocess.run(
        [sys.executable, "-m", "rosl", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=timeout,
        env={**os.environ, "PYTHONUNBUFFERED": "1", **(env or {})},
        check=False,
    )


# --- publishers --------------------------------------------------------------------------------

PUBLISHER = r"""
import json, sys, time
import rosl
from rosl.idl import registry
from rosl.idl.messages import from_dict
from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

spec = json.loads(sys.stdin.read())
rosl.init([])
node = rosl.Node(spec.get("node", "bag_test_talker"))
publishers = []
for entry in spec["publishers"]:
    words = entry.get("qos", {})
    qos = QoSProfile(
        depth=words.get("depth", 10),
        durability=DurabilityPolicy[words.get("durability", "VOLATILE")],
        reliability=ReliabilityPolicy[words.get("reliability", "RELIABLE")],
    )
    publishers.append(node.create_publisher(registry.get_message_class(entry["type"]), entry["topic"], qos))
deadline = time.monotonic() + spec.get("wait_timeout", 30.0)
for entry, publisher in zip(spec["publishers"], publishers):
    wanted = entry.get("wait", spec.get("wait_subscribers", 1))
    while publisher.get_subscription_count() < wanted and time.monotonic() < deadline:
        time.sleep(0.02)
    if publisher.get_subscription_count() < wanted:
        print("NO SUBSCRIBER on " + publisher.topic, flush=True)
        sys.exit(3)
time.sleep(spec.get("settle", 0.2))
print("READY", flush=True)
for line in spec.get("log", []):
    node.get_logger().info(line)
period = spec.get("period", 0.0)
start = time.monotonic()
for index, (which, fields) in enumerate(spec["messages"]):
    if period:
        pause = start + index * period - time.monotonic()
        if pause > 0:
            time.sleep(pause)
    publisher = publishers[which]
    message = from_dict(publisher.msg_type, fields)
    before = time.time_ns()
    publisher.publish(message)
    after = time.time_ns()
    print(json.dumps({"i": index, "before": before, "after": after}), flush=True)
time.sleep(spec.get("linger", 0.5))
print("DONE", flush=True)
node.destroy_node()
rosl.shutdown()
"""


def start_publisher(processes: Processes, spec: dict[str, Any], cwd: Path | None = None) -> Child:
    """A publisher child running ``spec`` (see ``PUBLISHER``)."""
    popen = processes.python(PUBLISHER, cwd=cwd, stdin=subprocess.PIPE)
    assert popen.stdin is not None
    popen.stdin.write(json.dumps(spec))
    popen.stdin.close()
    return Child(popen)


def run_publisher(
    processes: Processes, spec: dict[str, Any], cwd: Path | None = None, timeout: float = 30.0
) -> list[dict[str, int]]:
    """Run a publisher to its end; its per-message send times, in order."""
    child = start_publisher(processes, spec, cwd=cwd)
    code = child.finish(timeout)
    assert code == 0, f"the publisher failed ({code})\n{child.both()}"
    return sent_times(child)


def sent_times(child: Child) -> list[dict[str, int]]:
    return [json.loads(line) for line in child.lines() if line.startswith("{")]


# --- the bag on disk ---------------------------------------------------------------------------


def metadata(folder: Path) -> dict[str, Any]:
    data = yaml.safe_load((folder / "metadata.yaml").read_text())
    return data["rosbag2_bagfile_information"]


def channel_hashes(folder: Path) -> dict[str, str]:
    """Each topic's RIHS01 hash, as its MCAP channels carry it (``topic_type_hash``)."""
    return {
        topic: channel.metadata.get("topic_type_hash", "")
        for mcap_file in read_mcap(folder)
        for topic, channel in mcap_file.channels.items()
    }


def topic_counts(folder: Path) -> dict[str, int]:
    return {
        entry["topic_metadata"]["name"]: entry["message_count"]
        for entry in metadata(folder)["topics_with_message_count"]
    }


def bag_files(folder: Path) -> list[Path]:
    """The bag's files in metadata order (or by their split index without metadata)."""
    if (folder / "metadata.yaml").is_file():
        return [folder / name for name in metadata(folder)["relative_file_paths"]]

    def split_index(path: Path) -> tuple[str, int]:
        stem, _, index = path.stem.rpartition("_")
        return (stem, int(index)) if index.isdigit() else (path.stem, -1)

    return sorted(folder.glob("*.mcap"), key=split_index)


def complete_messages(path: Path) -> list[bytes]:
    """The payloads of the complete message records of a (possibly cut) MCAP file."""
    from mcap.records import Message
    from mcap.stream_reader import StreamReader

    found = []
    with path.open("rb") as handle:
        try:
            for record in StreamReader(handle, skip_magic=False, emit_chunks=False).records:
                if isinstance(record, Message):
                    found.append(bytes(record.data))
        except Exception:  # the torn tail of the file
            pass
    return found


def typestore_from(definitions: list[tuple[str, str, str]]) -> Any:
    """A rosbags type store from (type, encoding, text) definitions as stored in a bag."""
    from rosbags.typesys import Stores, get_types_from_idl, get_types_from_msg, get_typestore

    types: dict[str, Any] = {}
    for name, encoding, text in definitions:
        if encoding == "ros2msg":
            types.update(get_types_from_msg(text, name))
        elif encoding == "ros2idl":
            for section in text.split("=" * 80 + "\n")[1:]:
                header, idl = section.split("\n", 1)
                assert header.startswith("IDL: "), header
                types.update(get_types_from_idl(idl))
        else:
            raise AssertionError(f"unexpected schema encoding {encoding!r} for {name}")
    store = get_typestore(Stores.EMPTY)
    store.register(types)
    return store


def rihs01(type_name: str, encoding: str, text: str) -> str:
    """rosbags' RIHS01 hash of a type, from its definition text."""
    return str(typestore_from([(type_name, encoding, text)]).hash_rihs01(type_name))


def plain(value: Any) -> Any:
    """rosbags or rosl messages (and their field values) as plain, comparable data."""
    from rosl.idl.base import Message

    if isinstance(value, Message):
        return {name: plain(getattr(value, name)) for name in value._fields}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        # rosbags' classes list constants and __msgtype__ as (ClassVar-annotated) fields
        return {
            f.name: plain(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if f.name != "structure_needs_at_least_one_member"
            and not str(f.type).startswith(("ClassVar", "typing.ClassVar"))
        }
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "biuf":  # numbers: tolist() gives plain ones (fast for images)
            return value.tolist()
        return [plain(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


@dataclasses.dataclass
class Read:
    """One message as a reader saw it."""

    topic: str
    type: str
    log_time: int
    data: bytes
    fields: Any
    publish_time: int = 0
    sequence: int = 0


def read_anyreader(folder: Path) -> list[Read]:
    from rosbags.highlevel import AnyReader

    found = []
    with AnyReader([folder]) as reader:
        for connection, timestamp, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            found.append(
                Read(connection.topic, connection.msgtype, timestamp, bytes(raw), plain(message))
            )
    return found


def read_rosbag2(folder: Path) -> list[Read]:
    from rosbags.rosbag2 import Reader

    found = []
    with Reader(folder) as reader:
        store = typestore_from(
            [
                (
                    c.msgtype,
                    {"MSG": "ros2msg", "IDL": "ros2idl"}[c.msgdef.format.name],
                    c.msgdef.data,
                )
                for c in reader.connections
                if c.msgdef.format.name != "NONE"  # a topic subscribed to but never heard
            ]
        )
        for connection, timestamp, raw in reader.messages():
            message = store.deserialize_cdr(raw, connection.msgtype)
            found.append(
                Read(connection.topic, connection.msgtype, timestamp, bytes(raw), plain(message))
            )
    return found


@dataclasses.dataclass
class McapFile:
    """What ``mcap``'s reader sees in one file."""

    profile: str
    library: str
    schemas: dict[str, tuple[str, str]]  # type -> (encoding, text)
    channels: dict[str, Any]  # topic -> channel record
    messages: list[Read]
    statistics: Any


def read_mcap_file(path: Path) -> McapFile:
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        reader = make_reader(handle)
        header = reader.get_header()
        summary = reader.get_summary()
        assert summary is not None, f"{path} has no summary"
        schemas = {s.name: (s.encoding, s.data.decode()) for s in summary.schemas.values()}
        channels = {c.topic: c for c in summary.channels.values()}
        raw = [
            (schema, channel, message)
            for schema, channel, message in reader.iter_messages(log_time_order=False)
        ]
    store = typestore_from([(name, enc, text) for name, (enc, text) in schemas.items()])
    messages = [
        Read(
            channel.topic,
            schema.name,
            message.log_time,
            bytes(message.data),
            plain(store.deserialize_cdr(bytes(message.data), schema.name)),
            message.publish_time,
            message.sequence,
        )
        for schema, channel, message in raw
    ]
    return McapFile(header.profile, header.library, schemas, channels, messages, summary.statistics)


def read_mcap(folder: Path) -> list[McapFile]:
    return [read_mcap_file(path) for path in bag_files(folder)]


def by_topic(messages: list[Read]) -> dict[str, list[Read]]:
    found: dict[str, list[Read]] = {}
    for message in messages:
        found.setdefault(message.topic, []).append(message)
    return found


def sent_message(type_name: str, fields: dict[str, Any]) -> Any:
    """The message the publisher built from ``fields`` (built the same way here)."""
    from rosl.idl import registry
    from rosl.idl.messages import from_dict

    return from_dict(registry.get_message_class(type_name), fields)


def cdr(type_name: str, fields: dict[str, Any]) -> bytes:
    """The CDR bytes rosl's publisher sends for ``fields``."""
    from rosl.idl import registry

    return registry.store().serialize(sent_message(type_name, fields))
