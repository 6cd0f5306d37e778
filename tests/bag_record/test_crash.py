"""Crash safety: SIGKILL loses at most the last second and ``rosl bag reindex`` repairs the
folder; SIGINT and SIGTERM finish a complete, indexed file with its metadata.yaml.

A publisher sends Int32 1..N at 50 Hz and prints the wall-clock time around each publish; the
recorders are signalled while it is publishing. The recorder flushes every second, so every
message published more than 3 s before a SIGKILL (the flush period, and slack for a loaded
machine) must be in the repaired bag, and what is there must be exactly a prefix 1..K of what
was sent.
"""

from __future__ import annotations

import shutil
import signal
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import pytest
import yaml

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path
    from subprocess import CompletedProcess

    from tests.bag_record.conftest import DomainProcesses

pytestmark = pytest.mark.slow

MAGIC = b"\x89MCAP0\r\n"
RATE = 50.0
COUNTER = {"topic": "/counter", "type": "std_msgs/msg/Int32"}


def counter_spec(count: int, node: str, wait: int = 1) -> dict[str, object]:
    return {
        "node": node,
        "wait_subscribers": wait,
        "publishers": [COUNTER],
        "messages": [(0, {"data": value}) for value in range(1, count + 1)],
        "period": 1.0 / RATE,
    }


def has_footer(path: Path) -> bool:
    data = path.read_bytes()
    return data.startswith(MAGIC) and data.endswith(MAGIC) and len(data) > 2 * len(MAGIC)


@dataclass
class Killed:
    raw: Path  # a copy of the folder as the killed recorder left it
    folder: Path  # the folder after `rosl bag reindex`
    kill_ns: int
    times: list[dict[str, int]]  # per value 1..N: send times
    reindex: CompletedProcess[str]


@pytest.fixture(scope="module")
def killed(module_bus: DomainProcesses, module_dir: Path) -> Killed:
    folder = module_dir / "killed"
    recorder = support.start_recorder(module_bus, "-a", "-o", str(folder), cwd=module_dir)
    publisher = support.start_publisher(module_bus, counter_spec(300, "crash_talker"), module_dir)
    # let it publish for about 5 s, then kill the recorder while messages keep coming
    assert publisher.wait_count(r'^\{"i": ', 250, timeout=60), publisher.both()
    kill_ns = time.time_ns()
    recorder.popen.send_signal(signal.SIGKILL)
    assert recorder.finish(10) == -signal.SIGKILL
    assert publisher.finish(30) == 0, publisher.both()
    times = support.sent_times(publisher)
    assert len(times) == 300
    raw = module_dir / "killed_raw"
    shutil.copytree(folder, raw)
    reindex = support.rosl_run("bag", "reindex", str(folder))
    return Killed(raw, folder, kill_ns, times, reindex)


def test_a_killed_recorder_leaves_an_unfinished_mcap_file(killed: Killed) -> None:
    files = sorted(killed.raw.glob("*.mcap"))
    assert len(files) == 1
    data = files[0].read_bytes()
    assert data.startswith(MAGIC)
    assert not data.endswith(MAGIC), "a killed recorder cannot have written the footer"
    assert not (killed.raw / "metadata.yaml").exists()


def test_the_unfinished_file_already_holds_flushed_messages(killed: Killed) -> None:
    from mcap.stream_reader import StreamReader

    (path,) = killed.raw.glob("*.mcap")
    found = 0
    with path.open("rb") as handle:
        records = StreamReader(handle, skip_magic=False, emit_chunks=False).records
        try:
            for record in records:
                found += type(record).__name__ == "Message"
        except Exception:  # the torn tail of the file
            pass
    assert found > 0, "nothing was flushed to disk in 5 s of recording"


def test_bag_info_on_a_killed_recording_says_it_is_unfinished_and_suggests_reindex(
    killed: Killed, tmp_path: Path
) -> None:
    copy = tmp_path / "copy"
    shutil.copytree(killed.raw, copy)
    result = support.rosl_run("bag", "info", str(copy))
    said = result.stdout + result.stderr
    assert "unfinished" in said
    assert "reindex" in said
    assert result.returncode == 0, said  # what is complete is shown; the repair is suggested
    assert "Traceback" not in said
    # info does not repair anything by itself
    assert sorted(p.name for p in copy.iterdir()) == sorted(p.name for p in killed.raw.iterdir())


def test_reindex_rewrites_the_unfinished_file_and_writes_metadata(killed: Killed) -> None:
    assert killed.reindex.returncode == 0, killed.reindex.stderr
    assert "unfinished" in killed.reindex.stdout
    (path,) = support.bag_files(killed.folder)
    assert has_footer(path)
    info = support.metadata(killed.folder)
    assert info["storage_identifier"] == "mcap"
    counts = support.topic_counts(killed.folder)
    content = support.read_mcap_file(path)
    assert counts["/counter"] == sum(1 for m in content.messages if m.topic == "/counter")
    assert info["message_count"] == len(content.messages)
    assert content.profile == "ros2"


def test_reindex_keeps_the_offered_qos_the_unfinished_files_channels_carry(
    killed: Killed,
) -> None:
    """The killed file's channel records hold offered_qos_profiles; reindex must not drop it."""
    from mcap.records import Channel
    from mcap.stream_reader import StreamReader

    (raw,) = killed.raw.glob("*.mcap")
    offered = {}
    with raw.open("rb") as handle:
        try:
            for record in StreamReader(handle, skip_magic=False, emit_chunks=False).records:
                if isinstance(record, Channel):
                    offered[record.topic] = record.metadata.get("offered_qos_profiles", "")
        except Exception:  # the torn tail of the file
            pass
    assert yaml.safe_load(offered["/counter"])[0]["depth"] == 10
    entries = {  # a YAML text in the layout of Humble (the default label), a list from Jazzy on
        e["topic_metadata"]["name"]: (
            yaml.safe_load(qos) if isinstance(qos := e["topic_metadata"]["offered_qos_profiles"], str)
            else qos
        )
        for e in support.metadata(killed.folder)["topics_with_message_count"]
    }  # fmt: skip
    assert entries["/counter"] == yaml.safe_load(offered["/counter"])
    (path,) = support.bag_files(killed.folder)
    channel = support.read_mcap_file(path).channels["/counter"]
    assert yaml.safe_load(channel.metadata.get("offered_qos_profiles", "")) == entries["/counter"]


def test_the_recovered_counter_is_exactly_a_prefix_of_what_was_published(
    killed: Killed,
) -> None:
    values = [
        m.fields["data"]
        for m in support.by_topic(support.read_anyreader(killed.folder))["/counter"]
    ]
    assert values == list(range(1, len(values) + 1))
    # nothing sent after the kill can be there
    for value in values:
        assert killed.times[value - 1]["before"] < killed.kill_ns, value


def test_every_message_published_over_3_s_before_the_kill_survived(killed: Killed) -> None:
    values = [
        m.fields["data"]
        for m in support.by_topic(support.read_anyreader(killed.folder))["/counter"]
    ]
    # flushed once a second: 3 s leaves room for a recorder slowed down by a loaded machine,
    # while a recorder that only wrote at its end would keep nothing
    must = [
        i + 1 for i, t in enumerate(killed.times) if t["after"] < killed.kill_ns - 3_000_000_000
    ]
    assert must, "the kill came too early to test the bound"
    assert len(values) >= must[-1], (len(values), must[-1])


def test_all_three_readers_read_the_repaired_bag_with_the_sent_bytes(killed: Killed) -> None:
    anyreader = support.by_topic(support.read_anyreader(killed.folder))["/counter"]
    rosbag2 = support.by_topic(support.read_rosbag2(killed.folder))["/counter"]
    mcap = support.by_topic([m for f in support.read_mcap(killed.folder) for m in f.messages])[
        "/counter"
    ]
    expected = [support.cdr("std_msgs/msg/Int32", {"data": v + 1}) for v in range(len(anyreader))]
    assert [m.data for m in anyreader] == expected
    assert [m.data for m in rosbag2] == expected
    assert [m.data for m in mcap] == expected
    assert [m.sequence for m in mcap] == list(range(1, len(mcap) + 1))
    for message in mcap:
        value = message.fields["data"]
        sent = killed.times[value - 1]
        assert sent["before"] <= message.publish_time <= sent["after"]
        assert message.publish_time <= message.log_time


@dataclass
class Stopped:
    folder: Path
    signal_ns: int
    stderr: str
    times: list[dict[str, int]] = field(default_factory=list)


@pytest.fixture(scope="module")
def stopped(module_bus: DomainProcesses, module_dir: Path) -> dict[str, Stopped]:
    folders = {"SIGINT": module_dir / "by_sigint", "SIGTERM": module_dir / "by_sigterm"}
    recorders = {
        name: support.start_recorder(module_bus, "-a", "-o", str(path), cwd=module_dir)
        for name, path in folders.items()
    }
    publisher = support.start_publisher(
        module_bus, counter_spec(150, "stop_talker", wait=2), module_dir
    )
    found = {}
    for name, after in (("SIGTERM", 80), ("SIGINT", 110)):
        assert publisher.wait_count(r'^\{"i": ', after, timeout=60), publisher.both()
        signal_ns = time.time_ns()
        stderr = support.stop_recorder(recorders[name], getattr(signal, name))
        found[name] = Stopped(folders[name], signal_ns, stderr)
    assert publisher.finish(30) == 0, publisher.both()
    times = support.sent_times(publisher)
    for entry in found.values():
        entry.times = times
    return found


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signalled_recorder_finishes_a_complete_indexed_file(
    stopped: dict[str, Stopped], name: str
) -> None:
    entry = stopped[name]
    files = support.bag_files(entry.folder)
    assert len(files) == 1
    assert has_footer(files[0])
    content = support.read_mcap_file(files[0])  # through the summary and its index
    counts = support.topic_counts(entry.folder)
    assert counts["/counter"] == sum(1 for m in content.messages if m.topic == "/counter")
    assert "Recording stopped" in entry.stderr


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
def test_a_signalled_recorder_keeps_everything_before_the_signal(
    stopped: dict[str, Stopped], name: str
) -> None:
    entry = stopped[name]
    times = entry.times
    values = [
        m.fields["data"] for m in support.by_topic(support.read_anyreader(entry.folder))["/counter"]
    ]
    assert values == list(range(1, len(values) + 1))
    # a clean stop loses nothing that was on the bus well before it
    sent_before = [i + 1 for i, t in enumerate(times) if t["after"] < entry.signal_ns - 500_000_000]
    assert len(values) >= sent_before[-1]
