"""Which topics a recorder takes: named topics, ``--exclude REGEX``, and how others see it.

Three recorders run at once on one domain: ``rosl bag record /wanted /also``,
``rosl bag record -a --exclude '^/(also|noise)'`` and ``rosl bag record wanted`` (a relative
name, which ros2 bag record expands to ``/wanted``). One publisher sends on /wanted, /also and
/noise; then ``rosl topic pub --once /ping`` and ``rosl node list`` run while both record.
"""

from __future__ import annotations

import re
import signal
from dataclasses import dataclass
from typing import TYPE_CHECKING

import pytest

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path
    from subprocess import CompletedProcess

    from tests.bag_record.conftest import DomainProcesses

PUBLISHERS = [
    {"topic": "/wanted", "type": "std_msgs/msg/String", "wait": 3},
    {"topic": "/also", "type": "std_msgs/msg/Int32", "wait": 1},
    {"topic": "/noise", "type": "std_msgs/msg/Int32", "wait": 0},
]
MESSAGES = [
    *[(0, {"data": f"w{i}"}) for i in range(4)],
    *[(1, {"data": i}) for i in range(3)],
    *[(2, {"data": i}) for i in range(5)],
]


@dataclass
class Selection:
    named: Path
    excluded: Path
    relative: Path
    relative_stderr: str
    pub: CompletedProcess[str]
    node_list: CompletedProcess[str]


@pytest.fixture(scope="module")
def selection(module_bus: DomainProcesses, module_dir: Path) -> Selection:
    named_dir = module_dir / "named"
    excluded_dir = module_dir / "excluded"
    relative_dir = module_dir / "relative"
    named = support.start_recorder(
        module_bus, "/wanted", "/also", "-o", str(named_dir), cwd=module_dir
    )
    excluded = support.start_recorder(
        module_bus, "-a", "--exclude", "^/(also|noise)", "-o", str(excluded_dir), cwd=module_dir
    )
    relative = support.start_recorder(module_bus, "wanted", "-o", str(relative_dir), cwd=module_dir)
    support.run_publisher(
        module_bus,
        {"node": "selection_talker", "publishers": PUBLISHERS, "messages": MESSAGES,
         "log": ["selection says hi"]},
        cwd=module_dir,
    )  # fmt: skip
    pub = support.rosl_run(
        "topic", "pub", "--once", "/ping", "std_msgs/msg/String", "{data: ping}",
        cwd=module_dir, env={"ROSL_DOMAIN_ID": str(module_bus.domain)},
    )  # fmt: skip
    node_list = support.rosl_run(
        "node", "list", cwd=module_dir, env={"ROSL_DOMAIN_ID": str(module_bus.domain)}
    )
    support.stop_recorder(named, signal.SIGINT)
    support.stop_recorder(excluded, signal.SIGINT)
    relative_stderr = support.stop_recorder(relative, signal.SIGINT)
    return Selection(named_dir, excluded_dir, relative_dir, relative_stderr, pub, node_list)


def test_recording_named_topics_keeps_only_those_topics(selection: Selection) -> None:
    assert support.topic_counts(selection.named) == {"/wanted": 4, "/also": 3}
    messages = support.by_topic(support.read_anyreader(selection.named))
    assert [m.fields["data"] for m in messages["/wanted"]] == ["w0", "w1", "w2", "w3"]
    assert [m.fields["data"] for m in messages["/also"]] == [0, 1, 2]


def test_a_relative_topic_name_is_recorded_as_its_absolute_name(selection: Selection) -> None:
    assert support.topic_counts(selection.relative) == {"/wanted": 4}
    messages = support.by_topic(support.read_anyreader(selection.relative))
    assert [m.fields["data"] for m in messages["/wanted"]] == ["w0", "w1", "w2", "w3"]
    assert "Subscribed to topic '/wanted'" in selection.relative_stderr


def test_exclude_regex_leaves_out_the_matching_topics(selection: Selection) -> None:
    counts = support.topic_counts(selection.excluded)
    assert "/also" not in counts
    assert "/noise" not in counts
    assert counts["/wanted"] == 4
    assert "/rosout" in counts
    assert "/parameter_events" in counts
    channels = {t for f in support.read_mcap(selection.excluded) for t in f.channels}
    assert channels.isdisjoint({"/also", "/noise"})


def test_topic_pub_once_is_matched_by_the_recorder_and_recorded(selection: Selection) -> None:
    assert selection.pub.returncode == 0, selection.pub.stderr
    # the named recorder does not take /ping; the -a one does
    said = selection.pub.stdout + selection.pub.stderr
    assert re.search(r"\b1 matched subscription", said), said
    messages = support.by_topic(support.read_anyreader(selection.excluded))
    assert [m.fields["data"] for m in messages["/ping"]] == ["ping"]
    assert "/ping" not in support.topic_counts(selection.named)


def test_the_recorder_shows_up_as_node_rosbag2_recorder(selection: Selection) -> None:
    assert selection.node_list.returncode == 0, selection.node_list.stderr
    lines = selection.node_list.stdout.splitlines()
    assert "/rosbag2_recorder" in lines, lines
