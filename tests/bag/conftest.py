"""Fixtures for play, diff, filter and the golden-log helper.

``scenario_bag`` is recorded once per session by real processes — ``rosl bag record -a`` and a
node publishing /chatter, /numbers and /pose on a schedule with two 0.5 s gaps — on a domain
locked for the session. ``Listener`` is a rosl node in the test process that keeps the raw
bytes and send times of what it hears; ``mcap_messages`` reads a bag with the mcap library.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pytest

from tests.conftest import lock_domain

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

SCENARIO = r"""
import time
import rosl
from rosl.idl.registry import get_message_class

rosl.init([])
node = rosl.create_node("scenario")
String = get_message_class("std_msgs/msg/String")
Int32 = get_message_class("std_msgs/msg/Int32")
PoseStamped = get_message_class("geometry_msgs/msg/PoseStamped")
pubs = {
    "/chatter": node.create_publisher(String, "/chatter", 10),
    "/numbers": node.create_publisher(Int32, "/numbers", 10),
    "/pose": node.create_publisher(PoseStamped, "/pose", 10),
}
for pub in pubs.values():
    pub.wait_for_subscribers(1, 30.0)
time.sleep(0.3)

def make(topic, value):
    if topic == "/chatter":
        return String(data=value)
    if topic == "/numbers":
        return Int32(data=value)
    pose = PoseStamped()
    pose.header.stamp = node.get_clock().now().to_msg()
    pose.header.frame_id = "map"
    pose.pose.position.x = value
    pose.pose.orientation.w = 1.0
    return pose

PLAN = [
    (0.00, "/chatter", "m0"), (0.00, "/pose", 0.0),
    (0.10, "/numbers", 1), (0.10, "/chatter", "m1"),
    (0.60, "/chatter", "m2"), (0.60, "/pose", 1.0),
    (0.70, "/numbers", 2), (0.70, "/chatter", "m3"),
    (1.20, "/chatter", "m4"), (1.20, "/numbers", 3), (1.20, "/pose", 2.0),
]
start = time.monotonic()
for at, topic, value in PLAN:
    time.sleep(max(0.0, start + at - time.monotonic()))
    pubs[topic].publish(make(topic, value))
time.sleep(0.3)
rosl.shutdown()
"""
TYPES = {
    "/chatter": "std_msgs/msg/String",
    "/numbers": "std_msgs/msg/Int32",
    "/pose": "geometry_msgs/msg/PoseStamped",
}


@dataclass(frozen=True)
class Recorded:
    """One message read back with the mcap library."""

    topic: str
    type: str
    log_time: int
    publish_time: int
    sequence: int
    data: bytes


def mcap_messages(bag: Path, topics: set[str] | None = None) -> list[Recorded]:
    """Every message of a bag folder (or file), file by file, with the mcap library."""
    from mcap.reader import make_reader

    files = [bag] if bag.is_file() else sorted(bag.glob("*.mcap"))
    found = []
    for path in files:
        with path.open("rb") as handle:
            for schema, channel, message in make_reader(handle).iter_messages(
                topics=list(topics) if topics else None
            ):
                found.append(
                    Recorded(channel.topic, schema.name if schema else "", message.log_time,
                             message.publish_time, message.sequence, bytes(message.data))
                )  # fmt: skip
    return found


def _wait_for_text(path: Path, text: str, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in path.read_text(errors="replace"):
            return True
        time.sleep(0.05)
    return False


def _end(child: subprocess.Popen[bytes]) -> None:
    if child.poll() is None:
        child.send_signal(signal.SIGINT)
    try:
        child.wait(timeout=10)
    except subprocess.TimeoutExpired:
        child.kill()
        child.wait(timeout=5)


@pytest.fixture(scope="session")
def scenario_bag(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A bag recorded from real processes: /chatter (5), /numbers (3), /pose (3), 1.2 s."""
    folder = tmp_path_factory.mktemp("scenario")
    bag = folder / "scenario"
    domain, lock = lock_domain()
    env = {**os.environ, "ROSL_DOMAIN_ID": str(domain), "PYTHONUNBUFFERED": "1"}
    env.pop("ROSL_PACKAGE_PATH", None)
    log = folder / "recorder.log"
    children: list[subprocess.Popen[bytes]] = []
    try:
        with log.open("w") as out:
            recorder = subprocess.Popen(
                [sys.executable, "-m", "rosl", "bag", "record", "-a", "-o", str(bag)],
                stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env,
                cwd=folder, start_new_session=True,
            )  # fmt: skip
            children.append(recorder)
            assert _wait_for_text(log, "Recording to", 30.0), log.read_text()
            scenario = subprocess.Popen(
                [sys.executable, "-c", SCENARIO], env=env, cwd=folder, start_new_session=True,
                stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
            )  # fmt: skip
            children.append(scenario)
            assert scenario.wait(timeout=60) == 0, log.read_text()
            _end(recorder)
        counts = {t: sum(1 for m in mcap_messages(bag) if m.topic == t) for t in TYPES}
        assert counts == {"/chatter": 5, "/numbers": 3, "/pose": 3}, log.read_text()
        yield bag
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()
                child.wait(timeout=5)
        lock.close()


class Listener:
    """A node in the test process keeping (topic, bytes, send time) of what it hears."""

    def __init__(self, rosl: Any, topics: dict[str, str], **node_options: Any) -> None:
        from rosl.idl.registry import get_message_class

        self.rosl = rosl
        self.node = rosl.create_node("bag_test_listener", **node_options)
        self.heard: list[tuple[str, bytes, int]] = []
        for name, type_name in topics.items():
            self.node.create_subscription(
                get_message_class(type_name), name, self._callback(name), 100, raw=True
            )

    def _callback(self, topic: str) -> Callable[[bytes, dict[str, Any]], None]:
        def heard(data: bytes, info: dict[str, Any]) -> None:
            self.heard.append((topic, bytes(data), info["source_timestamp"]))

        return heard

    def spin_until(self, done: Callable[[], bool], timeout: float = 30.0) -> bool:
        """Spin until ``done()`` or the (bounded) timeout."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if done():
                return True
            self.rosl.spin_once(self.node, timeout_sec=0.02)
        return done()

    def spin_while_running(self, child: subprocess.Popen[str], timeout: float = 30.0) -> None:
        """Spin while ``child`` runs, then a little longer for the last datagrams."""
        self.spin_until(lambda: child.poll() is not None, timeout)
        # its last datagrams are on this process's sockets already: read until a pass brings
        # nothing new, for at least 0.2 s and at least one pass however slow the machine is
        end, bound = time.monotonic() + 0.2, time.monotonic() + 10.0
        while time.monotonic() < bound:
            before = len(self.heard)
            self.rosl.spin_once(self.node, timeout_sec=0.05)
            if len(self.heard) == before and time.monotonic() > end:
                break

    def on(self, topic: str) -> list[tuple[bytes, int]]:
        """(bytes, send time) heard on one topic, in order."""
        return [(data, stamp) for name, data, stamp in self.heard if name == topic]


def rewrite(source: Path, target: Path, edit: Callable[[Recorded], Recorded | None]) -> Path:
    """Copy a bag into a new folder through ``edit`` (None drops a message), metadata included."""
    import shutil

    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    target.mkdir(parents=True)
    for path in sorted(source.glob("*.mcap")):
        with path.open("rb") as handle, (target / path.name).open("wb") as out:
            reader = make_reader(handle)
            writer = Writer(out, compression=CompressionType.NONE)
            writer.start(profile="ros2", library="test")
            schemas: dict[int, int] = {}
            channels: dict[int, int] = {}
            for schema, channel, message in reader.iter_messages():
                if channel.id not in channels:
                    if schema.id not in schemas:
                        schemas[schema.id] = writer.register_schema(
                            schema.name, schema.encoding, schema.data
                        )
                    channels[channel.id] = writer.register_channel(
                        channel.topic, channel.message_encoding, schemas[schema.id],
                        channel.metadata,
                    )  # fmt: skip
                record = Recorded(channel.topic, schema.name, message.log_time,
                                  message.publish_time, message.sequence, bytes(message.data))  # fmt: skip
                changed = edit(record)
                if changed is not None:
                    writer.add_message(channels[channel.id], changed.log_time, changed.data,
                                       changed.publish_time, changed.sequence)  # fmt: skip
            writer.finish()
    if (source / "metadata.yaml").is_file():
        shutil.copyfile(source / "metadata.yaml", target / "metadata.yaml")
    return target


def edit_field(record: Recorded, change: Callable[[Any], None]) -> Recorded:
    """Decode a message with the local types, change it, encode it again."""
    import dataclasses

    from rosl.idl import registry

    registry.get_message_class(record.type)
    message = registry.store().deserialize(record.data, record.type)
    change(message)
    return dataclasses.replace(record, data=registry.store().serialize(message))


def torn_bag(source: Path, folder: Path) -> Path:
    """A folder with one unchunked MCAP file of the source's /chatter, cut before its end.

    The file has no footer and its last message is torn: 4 of the 5 messages are complete.
    """
    from mcap.writer import Writer

    folder.mkdir()
    path = folder / f"{folder.name}_0.mcap"
    with path.open("wb") as handle:
        writer = Writer(handle, use_chunking=False)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        channel = writer.register_channel("/chatter", "cdr", schema)
        for message in mcap_messages(source, {"/chatter"}):
            writer.add_message(channel, message.log_time, message.data, message.publish_time)
        handle.flush()
        size = handle.tell()
    with path.open("r+b") as handle:
        handle.truncate(size - 10)
    return folder
