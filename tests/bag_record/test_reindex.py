"""``rosl bag reindex`` on odd folders: files that are not MCAP, many split files without a
metadata.yaml, a disk that refuses the rewrite, compressed recordings, topics with no messages,
files cut inside a chunk, chunks whose CRC fails, folders that are already whole.

Three recorders run at once while one publisher sends a counter (Int32 1..50 at 20 Hz) on
/counter and nothing on /silent: one records both topics with zstd chunks into one file
(several chunks, since chunks go out every second), one the same without compression and
labelled ``jazzy``, the other records /counter with lz4 and ``--max-bag-size 1``, so every
message gets a file of its own (``split_0`` .. ``split_49``). Files with chunks large enough to
hold several compressed blocks are written with the mcap library's Writer. Each test alters a
copy of those folders.
"""

from __future__ import annotations

import json
import os
import random
import shutil
import signal
import struct
import subprocess
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pytest

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import DomainProcesses

pytestmark = pytest.mark.slow

COUNT = 50
COUNTER = [support.cdr("std_msgs/msg/Int32", {"data": v}) for v in range(1, COUNT + 1)]


@dataclass
class Recorded:
    zstd: Path
    split: Path
    plain: Path  # no compression, labelled jazzy


@pytest.fixture(scope="module")
def recorded(module_bus: DomainProcesses, module_dir: Path) -> Recorded:
    found = Recorded(module_dir / "zstd", module_dir / "split", module_dir / "plain")
    recorders = [
        support.start_recorder(module_bus, "/counter", "/silent", "--compression-format", "zstd",
                               "-o", str(found.zstd), cwd=module_dir),
        support.start_recorder(module_bus, "/counter", "--compression-format", "lz4",
                               "--max-bag-size", "1", "-o", str(found.split), cwd=module_dir),
        support.start_recorder(module_bus, "/counter", "/silent", "--distro", "jazzy",
                               "-o", str(found.plain), cwd=module_dir),
    ]  # fmt: skip
    support.run_publisher(
        module_bus,
        {"node": "reindex_talker", "period": 0.05,
         "publishers": [{"topic": "/counter", "type": "std_msgs/msg/Int32", "wait": 3},
                        {"topic": "/silent", "type": "std_msgs/msg/String", "wait": 2}],
         "messages": [(0, {"data": v}) for v in range(1, COUNT + 1)]},
        cwd=module_dir,
    )  # fmt: skip
    for recorder in recorders:
        support.stop_recorder(recorder, signal.SIGINT)
    assert support.topic_counts(found.zstd) == {"/counter": COUNT, "/silent": 0}
    assert support.topic_counts(found.plain) == {"/counter": COUNT, "/silent": 0}
    assert len(list(found.split.glob("*.mcap"))) == COUNT
    return found


def copy_of(folder: Path, tmp_path: Path) -> Path:
    copy = tmp_path / folder.name
    shutil.copytree(folder, copy)
    return copy


def snapshot(folder: Path) -> dict[str, bytes]:
    return {
        p.name: p.read_bytes() if p.is_file() else b"<folder>" for p in sorted(folder.iterdir())
    }


def cut_in_half(path: Path) -> int:
    """Truncate ``path`` in the middle of its data; how many of its messages stay whole."""
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    cut = path.stat().st_size // 2
    whole = [c for c in summary.chunk_indexes if c.chunk_start_offset + c.chunk_length <= cut]
    assert whole, "the cut leaves no complete chunk; the recording is too small"
    with path.open("r+b") as handle:
        handle.truncate(cut)
    return len(support.complete_messages(path))


# --- a file that is not MCAP -------------------------------------------------------------------


def test_reindex_refuses_a_file_that_is_not_mcap_and_changes_nothing(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    (real,) = folder.glob("*.mcap")
    cut_in_half(real)  # an unfinished file reindex would otherwise rewrite
    (folder / "zstd_1.mcap").write_text("notes, not a recording\n")
    before = snapshot(folder)
    line = support.one_line_error(support.rosl_run("bag", "reindex", str(folder)))
    assert "zstd_1.mcap" in line
    assert "not an MCAP file" in line
    assert snapshot(folder) == before


def test_reindex_of_a_folder_holding_only_a_non_mcap_file_leaves_it_whole(tmp_path: Path) -> None:
    folder = tmp_path / "bag"
    folder.mkdir()
    fake = folder / "bag_0.mcap"
    fake.write_bytes(b"PK\x03\x04 a zip file named like a recording" * 10)
    before = snapshot(folder)
    line = support.one_line_error(support.rosl_run("bag", "reindex", str(folder)))
    assert "bag_0.mcap" in line
    assert "not an MCAP file" in line
    assert snapshot(folder) == before


# --- split files without metadata.yaml ---------------------------------------------------------


def test_split_files_without_metadata_are_read_and_reindexed_in_numeric_order(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.split, tmp_path)
    (folder / "metadata.yaml").unlink()
    in_order = [f"split_{i}.mcap" for i in range(COUNT)]

    info = support.rosl_run("bag", "info", "--json", str(folder))
    assert info.returncode == 0, info.stderr
    assert json.loads(info.stdout)["files"] == in_order

    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    meta = support.metadata(folder)
    assert meta["relative_file_paths"] == in_order
    assert [f["path"] for f in meta["files"]] == in_order
    starts = [f["starting_time"]["nanoseconds_since_epoch"] for f in meta["files"]]
    assert starts == sorted(starts)
    # each file holds one message: in file order they are the counter 1..50
    values = [m.fields["data"] for path in support.bag_files(folder)
              for m in support.read_mcap_file(path).messages]  # fmt: skip
    assert values == list(range(1, COUNT + 1))
    assert [m.data for m in support.read_rosbag2(folder)] == COUNTER


# --- a disk that refuses the rewrite -----------------------------------------------------------

# reindex in a process whose files may not grow past a limit: writes fail as on a full disk
LIMITED = r"""
import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
os.execv(sys.executable, [sys.executable, "-m", "rosl", *sys.argv[2:]])
"""


def test_reindex_on_a_full_disk_says_so_in_one_line_and_leaves_the_original(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    (path,) = folder.glob("*.mcap")
    cut_in_half(path)
    before = snapshot(folder)
    limit = 256  # well below what the rewritten file needs
    assert path.stat().st_size > limit
    result = subprocess.run(
        [sys.executable, "-c", LIMITED, str(limit), "bag", "reindex", str(folder)],
        capture_output=True, text=True, timeout=60, check=False,
        env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"},
    )  # fmt: skip
    line = support.one_line_error(result)
    assert path.name in line
    assert snapshot(folder) == before  # no *.mcap.reindex left behind, the original untouched
    # with room on the disk, the same folder is repaired
    repaired = support.rosl_run("bag", "reindex", str(folder))
    assert repaired.returncode == 0, repaired.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["metadata.yaml", path.name]
    assert path.stat().st_size > limit


# --- what a rewrite and a rebuilt metadata.yaml keep -------------------------------------------


def test_reindex_keeps_the_chunk_compression_of_the_recording(
    recorded: Recorded, tmp_path: Path
) -> None:
    from mcap.reader import make_reader

    folder = copy_of(recorded.zstd, tmp_path)
    (path,) = folder.glob("*.mcap")
    whole = cut_in_half(path)
    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    assert summary.chunk_indexes
    assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
    assert [m.data for m in support.read_anyreader(folder)] == COUNTER[:whole]


def test_reindex_keeps_the_topics_metadata_listed_without_messages(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    old = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    (path,) = folder.glob("*.mcap")
    whole = cut_in_half(path)
    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    new = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    assert new["/silent"] == old["/silent"]  # type, QoS, hash, and Count: 0
    assert new["/silent"]["message_count"] == 0
    assert new["/counter"]["message_count"] == whole
    # rosbags reads the rebuilt folder (a topic with no channel is allowed)
    assert len(support.read_rosbag2(folder)) == whole


# --- files cut inside a chunk, chunks whose CRC fails ------------------------------------------

RECORD = struct.Struct("<BQ")  # opcode, length
MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time
Sent = tuple[str, int, bytes]  # topic, log time, data


@pytest.fixture(scope="module")
def written(module_dir: Path) -> dict[str, Path]:
    """Folders of one file each, chunks of about 600 kB (several zstd and lz4 blocks)."""
    from mcap.writer import CompressionType, Writer

    words = random.Random(7)
    texts = [
        " ".join(words.choice(["alpha", "beta", str(i)]) for _ in range(250)) for i in range(800)
    ]
    found = {}
    for name, kind in (("zstd", CompressionType.ZSTD), ("lz4", CompressionType.LZ4)):
        folder = found[name] = module_dir / f"written_{name}"
        folder.mkdir()
        with (folder / f"written_{name}_0.mcap").open("wb") as handle:
            writer = Writer(handle, chunk_size=600_000, compression=kind)
            writer.start(profile="ros2", library="test")
            schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
            qos = "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 2\n"
            channel = writer.register_channel("/text", "cdr", schema, {"offered_qos_profiles": qos})
            for index, text in enumerate(texts):
                writer.add_message(channel, 1_000 + index, support.cdr("std_msgs/msg/String",
                                   {"data": text}), 1_000 + index, index + 1)  # fmt: skip
            writer.finish()
    return found


def summary_of(path: Path) -> Any:
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        return make_reader(handle).get_summary()


def chunk_records(data: bytes, index: Any) -> tuple[int, bytes]:
    """Where a chunk's (compressed) records start in the file, and those bytes."""
    start = index.chunk_start_offset + RECORD.size + 8 * 3 + 4 + 4 + len(index.compression) + 8
    return start, data[start : start + index.compressed_size]


def decompressed(compression: str, data: bytes) -> bytes:
    """What (a prefix of) a chunk's records decompresses to, by the libraries' own calls."""
    import lz4.frame
    import zstandard

    if compression == "zstd":
        return bytes(zstandard.ZstdDecompressor().decompressobj().decompress(data))
    if compression == "lz4":
        return bytes(lz4.frame.LZ4FrameDecompressor().decompress(data))
    return data


def messages_in(records: bytes, topics: dict[int, str]) -> list[tuple[int, Sent]]:
    """The messages of a chunk's records, each with where its record ends in them."""
    found, position = [], 0
    while position < len(records):
        opcode, length = RECORD.unpack_from(records, position)
        body = records[position + RECORD.size : position + RECORD.size + length]
        position += RECORD.size + length
        if opcode == 5:
            channel_id, _, log_time, _ = MESSAGE.unpack_from(body)
            found.append((position, (topics[channel_id], log_time, body[MESSAGE.size :])))
    return found


def cut_inside_a_chunk(path: Path) -> tuple[list[Sent], int, int]:
    """Truncate ``path`` in the middle of the records of its last chunk of several messages.

    Returns:
        The messages whose records the cut leaves whole (in the chunk cut, those within what
        its remaining bytes decompress to), how many of them are in the chunk cut, and how
        many that chunk held.
    """
    summary = summary_of(path)
    data = path.read_bytes()
    topics = {c.id: c.topic for c in summary.channels.values()}
    chunks = [(i, *chunk_records(data, i)) for i in summary.chunk_indexes]
    cut_chunk = [
        c for c in chunks if len(messages_in(decompressed(c[0].compression, c[2]), topics)) > 1
    ][-1]
    cut = cut_chunk[1] + len(cut_chunk[2]) // 2
    kept, in_cut, total = [], 0, 0
    for index, start, packed in chunks:
        readable = len(decompressed(index.compression, packed[: max(0, cut - start)]))
        for end, message in messages_in(decompressed(index.compression, packed), topics):
            kept += [message] if end <= readable else []
            if index is cut_chunk[0]:
                total += 1
                in_cut += end <= readable
    with path.open("r+b") as handle:
        handle.truncate(cut)
    return kept, in_cut, total


def every_message(path: Path) -> list[Sent]:
    summary = summary_of(path)
    data = path.read_bytes()
    topics = {c.id: c.topic for c in summary.channels.values()}
    return [m for i in summary.chunk_indexes
            for _, m in messages_in(decompressed(i.compression, chunk_records(data, i)[1]), topics)]  # fmt: skip


def read_back(folder: Path) -> list[Sent]:
    return sorted((m.topic, m.log_time, m.data) for m in support.read_anyreader(folder))


@pytest.mark.parametrize("kind", ["plain", "zstd", "lz4"])
def test_a_cut_inside_a_chunk_keeps_every_message_whose_record_was_complete_before_it(
    recorded: Recorded, written: dict[str, Path], kind: str, tmp_path: Path
) -> None:
    from rosl.bag.reindex import reindex

    folder = copy_of(recorded.plain if kind == "plain" else written[kind], tmp_path)
    (path,) = folder.glob("*.mcap")
    kept, from_cut, in_chunk = cut_inside_a_chunk(path)
    assert 0 < from_cut < in_chunk  # the chunk cut gives some of its messages, not all
    lines = reindex(folder)
    assert (
        f"{path.name}: was unfinished; rewritten with {len(kept)} messages "
        f"({from_cut} of them from a chunk cut short)"
    ) in lines
    assert not list(folder.glob("*.orig"))  # nothing complete was left out
    assert read_back(folder) == sorted(kept)  # finished, indexed, with its metadata.yaml
    compression = "" if kind == "plain" else kind
    assert {c.compression for c in summary_of(path).chunk_indexes} == {compression}


def test_reindex_keeps_the_bags_distro_label_and_each_channels_qos_and_hash(
    recorded: Recorded, tmp_path: Path
) -> None:
    from rosl.bag.reindex import reindex

    folder = copy_of(recorded.plain, tmp_path)
    (path,) = folder.glob("*.mcap")
    channels = {c.topic: c.metadata for c in summary_of(path).channels.values()}
    old = support.metadata(folder)
    cut_inside_a_chunk(path)
    reindex(folder)
    new = support.metadata(folder)
    assert (new["ros_distro"], new["version"]) == ("jazzy", 9)
    assert [e["topic_metadata"] for e in new["topics_with_message_count"]] == [
        e["topic_metadata"] for e in old["topics_with_message_count"]
    ]
    assert {c.topic: c.metadata for c in summary_of(path).channels.values()} == channels


def flip_a_message_byte(path: Path) -> tuple[int, list[Sent]]:
    """Flip the last byte of the first chunk holding messages (of an uncompressed file), inside
    its last message's data; the chunk's offset and the messages it held."""
    summary = summary_of(path)
    data = bytearray(path.read_bytes())
    topics = {c.id: c.topic for c in summary.channels.values()}
    for index in summary.chunk_indexes:
        start, records = chunk_records(bytes(data), index)
        inside = messages_in(records, topics)
        if inside and inside[-1][0] == len(records):
            data[start + len(records) - 1] ^= 0x01
            path.write_bytes(bytes(data))
            return index.chunk_start_offset, [m for _, m in inside]
    raise AssertionError("no chunk ends with a message")


def test_a_chunk_whose_crc_fails_is_reported_left_out_and_the_original_kept(
    recorded: Recorded, tmp_path: Path
) -> None:
    from rosl.bag.reindex import reindex

    folder = copy_of(recorded.plain, tmp_path)
    (path,) = folder.glob("*.mcap")
    every = every_message(path)
    offset, inside = flip_a_message_byte(path)
    flipped = path.read_bytes()
    lines = reindex(folder)
    assert (
        f"{path.name}: the chunk at byte {offset} fails its CRC check; "
        f"its {len(inside)} messages were left out"
    ) in lines
    assert (
        f"{path.name}: rewritten with {len(every) - len(inside)} messages; the original is kept as {path.name}.orig"
        in lines
    )
    assert (folder / f"{path.name}.orig").read_bytes() == flipped
    assert read_back(folder) == sorted(m for m in every if m not in inside)


def test_keep_corrupt_keeps_the_messages_of_a_chunk_whose_crc_fails(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.plain, tmp_path)
    (path,) = folder.glob("*.mcap")
    every = every_message(path)
    _, inside = flip_a_message_byte(path)
    result = support.rosl_run("bag", "reindex", "--keep-corrupt", str(folder))
    assert result.returncode == 0, result.stderr
    assert f"its {len(inside)} messages were kept (--keep-corrupt)" in result.stdout
    topic, log_time, data = inside[-1]
    changed = (topic, log_time, data[:-1] + bytes([data[-1] ^ 0x01]))
    assert read_back(folder) == sorted(changed if m == inside[-1] else m for m in every)
    assert not list(folder.glob("*.orig"))  # nothing was left out


def test_reindex_that_cannot_create_its_temporary_file_leaves_the_original_and_says_so(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    (path,) = folder.glob("*.mcap")
    cut_in_half(path)
    (folder / f"{path.name}.reindex").mkdir()  # where the new file would be written
    before = snapshot(folder)
    line = support.one_line_error(support.rosl_run("bag", "reindex", str(folder)))
    assert path.name in line
    assert snapshot(folder) == before


def test_reindex_of_a_whole_folder_says_so_and_changes_nothing(
    recorded: Recorded, tmp_path: Path
) -> None:
    from rosl.bag.reindex import reindex

    folder = copy_of(recorded.zstd, tmp_path)
    before = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in folder.iterdir()}
    (path,) = folder.glob("*.mcap")
    lines = reindex(folder)
    assert lines == [
        f"{path.name}: complete",
        "metadata.yaml: matches the files; nothing was changed",
    ]
    assert {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in folder.iterdir()} == before


def test_a_cut_file_without_a_complete_message_is_left_as_it_was_and_not_listed(
    recorded: Recorded, tmp_path: Path
) -> None:
    from rosl.bag.reindex import reindex

    folder = copy_of(recorded.split, tmp_path)
    last = folder / f"split_{COUNT - 1}.mcap"
    data = last.read_bytes()
    _, length = RECORD.unpack_from(data, 8)  # the header record, after the magic
    last.write_bytes(data[: 8 + RECORD.size + length + 20])  # cut in the record after it
    lines = reindex(folder)
    assert any(line.startswith(f"{last.name}: holds no complete message") for line in lines)
    assert last.read_bytes() == data[: 8 + RECORD.size + length + 20]
    assert support.metadata(folder)["relative_file_paths"] == [
        f"split_{i}.mcap" for i in range(COUNT - 1)
    ]
    assert [m.data for m in support.read_rosbag2(folder)] == COUNTER[:-1]
