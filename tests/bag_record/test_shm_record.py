"""Messages carried in shared memory are recorded byte for byte as the wire carries them.

``rosl bag record -a`` runs as a child, with a listener, next to a talker (``tests/bus/shm_snippets.py``) that
sends a 900 KB Image, a 100 KB and a 40 KB String per round through its shared-memory rings
(it reports how many went as descriptors) and a small String over the wire. The bag is read back
with ``mcap``'s reader, ``rosbags.rosbag2.Reader`` and ``AnyReader``: every message is the
CDR rosl serialises for it (the bytes the wire path sends), in order, decoded intact.
"""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

import numpy as np

from rosl.idl import registry
from tests.bag_record import support
from tests.bus import shm_snippets as snippets
from tests.bus.helpers import Lines

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

ROUNDS = 5


def expected() -> dict[str, list[bytes]]:
    """The CDR of every message the talker sends, by topic."""
    from sensor_msgs.msg import Image
    from std_msgs.msg import String

    store = registry.store()
    base = np.arange(snippets.IMAGE_BYTES)
    found: dict[str, list[bytes]] = {
        "/shm_image": [],
        "/shm_text": [],
        "/shm_mid": [],
        "/shm_small": [],
    }
    for i in range(ROUNDS):
        image = Image(height=480, width=640, encoding="rgb8", step=1920)
        image.header.frame_id = str(i)
        image.data = ((base + i) % 251).astype(np.uint8)
        found["/shm_image"].append(bytes(store.serialize(image)))
        found["/shm_text"].append(bytes(store.serialize(String(data=f"{i}:" + "x" * 100000))))
        found["/shm_mid"].append(bytes(store.serialize(String(data=f"{i}:" + "m" * 40000))))
        found["/shm_small"].append(bytes(store.serialize(String(data=f"{i}:small"))))
    return found


def test_messages_carried_in_shared_memory_are_recorded_as_sent(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "shm_bag"
    recorder = support.start_recorder(processes, "-a", "-o", str(folder), cwd=tmp_path)
    listener = processes.python(snippets.LISTENER, "shm_listener")
    heard = Lines(listener.stdout)
    assert heard.wait_line("up", 30.0), Lines(listener.stderr).rest(2.0)
    talker = processes.python(snippets.TALKER, str(ROUNDS), "2")  # the recorder and listener
    said = Lines(talker.stdout)
    line = said.wait_line("shm ", 60.0)
    assert line is not None, Lines(talker.stderr).rest(2.0)
    # the large and mid-size ones in shared memory
    assert line.split()[1:] == [str(ROUNDS), str(ROUNDS), str(ROUNDS), "0"]
    # once a subscriber has it all, what the recorder has not written yet is in its socket
    assert heard.wait_for(lambda lines: snippets.complete(lines, ROUNDS), 30.0), heard.lines
    support.stop_recorder(recorder, signal.SIGINT)
    want = expected()

    for read in (support.read_anyreader, support.read_rosbag2):
        topics = support.by_topic(read(folder))
        for topic, sent in want.items():
            assert [m.data for m in topics[topic]] == sent, topic
    (mcap_file,) = support.read_mcap(folder)
    topics = support.by_topic(mcap_file.messages)
    for topic, sent in want.items():
        assert [m.data for m in topics[topic]] == sent, topic
    images = topics["/shm_image"]
    assert [m.fields["header"]["frame_id"] for m in images] == [str(i) for i in range(ROUNDS)]
