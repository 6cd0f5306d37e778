"""``rosl launch tutorial_pkg my_launch.py --record DIR``: the whole run is in the bag.

The launch is stopped with SIGINT after the publisher has printed its third reading. The bag
must hold /my_data from counter 1 up to the last counter printed, and the nodes' last log
lines on /rosout: the recorder starts before the first node and stops after the last one.
"""

from __future__ import annotations

import re
import signal
from typing import TYPE_CHECKING

import pytest

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

NODE_LINE = re.compile(
    r"^\[(?P<label>[\w-]+)\] \[(?P<level>[A-Z]+)\] \[[\d.]+\] \[(?P<name>[\w/]+)\]: (?P<msg>.*)$"
)
NODES = ("my_publisher", "my_subscriber", "timer_node")


@pytest.mark.slow
def test_launch_record_holds_the_run_from_the_first_message_to_the_nodes_last_words(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "launch_bag"
    launch = support.Child(
        processes.rosl(
            "launch", "tutorial_pkg", "my_launch.py", "--record", str(folder),
            cwd=tmp_path, env={"ROSL_LOG_DIR": str(tmp_path / "log")},
        )
    )  # fmt: skip
    assert launch.wait_for(r"Publishing: counter=3 ", timeout=40), launch.both()
    code = launch.signal(signal.SIGINT, timeout=40)
    assert code == 0, launch.both()
    lines = launch.lines()

    # the recorder listened before any node started, and finished after all of them
    def index(pattern: str) -> int:
        found = [i for i, line in enumerate(lines) if re.search(pattern, line)]
        assert found, f"no line matches {pattern!r}\n{launch.both()}"
        return found[0]

    recording = index(r"\[rosbag2_recorder-\d+\] .*Recording to ")
    recorder_done = index(r"^\[INFO\] \[rosbag2_recorder-\d+\]: process has finished")
    for node in NODES:
        assert recording < index(rf"^\[INFO\] \[{node}-\d+\]: process started")
        assert index(rf"^\[INFO\] \[{node}-\d+\]: process has finished") < recorder_done

    # /my_data from counter 1 to (at least) the last one the publisher printed
    printed = [int(m) for m in re.findall(r"Publishing: counter=(\d+) ", "\n".join(lines))]
    messages = support.by_topic(support.read_anyreader(folder))
    counters = [m.fields["counter"] for m in messages["/my_data"]]
    assert counters[0] == 1
    assert counters == list(range(1, len(counters) + 1))
    assert len(counters) >= printed[-1]
    assert {m.fields["label"] for m in messages["/my_data"]} == {"reading"}

    # every node's last log line made it to the bag's /rosout
    last: dict[str, tuple[str, str]] = {}
    for line in lines:
        match = NODE_LINE.match(line)
        if match and match["label"].rsplit("-", 1)[0] in NODES:
            last[match["label"]] = (match["name"], match["msg"])
    assert len(last) == len(NODES), last
    logged = {(m.fields["name"], m.fields["msg"]) for m in messages["/rosout"]}
    for label, said in last.items():
        assert said in logged, (label, said)

    # the bag is whole: metadata, mcap's reader and rosbags agree on the counts
    counts = support.topic_counts(folder)
    assert counts["/my_data"] == len(counters)
    mcap = support.by_topic([m for f in support.read_mcap(folder) for m in f.messages])
    assert {t: len(v) for t, v in mcap.items()} == {t: n for t, n in counts.items() if n}


@pytest.mark.usefixtures("domain_id")
def test_launch_record_into_a_non_empty_folder_starts_no_node(tmp_path: Path) -> None:
    folder = tmp_path / "taken"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine\n")
    result = support.rosl_run(
        "launch", "tutorial_pkg", "my_launch.py", "--record", str(folder),
        cwd=tmp_path, env={"ROSL_LOG_DIR": str(tmp_path / "log")},
    )  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr
    assert "nothing was launched" in result.stderr
    for node in NODES:
        assert not re.search(rf"\[{node}-\d+\]: process started", result.stdout), result.stdout
    assert [p.name for p in folder.iterdir()] == ["keep.txt"]
    assert (folder / "keep.txt").read_text() == "mine\n"
