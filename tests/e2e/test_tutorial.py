"""The first tutorial end to end: its nodes run as real processes over the real bus."""

from __future__ import annotations

import itertools
import re
from typing import TYPE_CHECKING

import pytest

from rosl.graph.cache import LEASE_S
from tests.conftest import wait_until
from tests.graph.support import leaving_time, wait_for_node

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from rosl.node.node import Node
    from tests.graph.support import Watched

HEARD = r"\[my_subscriber\]: I heard: counter=(\d+) value=(-?\d+\.\d{3}) label='reading'"
TICK = r"^\[INFO\] \[(\d+\.\d+)\] \[timer_node\]: Tick (\d+) \(period ([\d.]+) s\)"
PERIOD_CHANGED = r"^\[INFO\] \[(\d+\.\d+)\] \[timer_node\]: Timer period changed to 0\.1 s"


def assert_clean_exit(child: Watched) -> None:
    code = child.interrupt()
    err = child.text("err")
    assert code == 0, f"exit code {code}\n{err}"
    assert "Traceback" not in err, err
    assert not child.matching(r"^\[(ERROR|FATAL)\]", "err"), err


@pytest.mark.slow
def test_the_tutorial_subscriber_hears_the_tutorial_publisher_counting_up(
    tutorial: Callable[..., Watched], observer_node: Node
) -> None:
    subscriber = tutorial("my_subscriber")
    assert observer_node.wait_for_node("/my_subscriber", 30.0), subscriber.text("err")
    assert wait_until(lambda: observer_node.count_subscribers("/my_data") == 1, timeout=30.0)

    publisher = tutorial("my_publisher")

    assert subscriber.wait_for(HEARD, "err", timeout=30.0, count=3), (
        f"subscriber:\n{subscriber.text('err')}\npublisher:\n{publisher.text('err')}"
    )
    counters = [int(m.group(1)) for m in subscriber.matching(HEARD, "err")]
    # the subscriber was listening before the first message: nothing missed, in order
    assert counters[:3] == [1, 2, 3]
    assert counters == list(range(1, len(counters) + 1))
    assert publisher.matching(r"\[my_publisher\]: Publishing: counter=1 value=0\.100", "err")

    assert_clean_exit(publisher)
    assert_clean_exit(subscriber)


def test_the_count_images_service_counts_the_images_in_a_folder(
    tutorial: Callable[..., Watched], observer_node: Node, tmp_path: Path
) -> None:
    from tutorial_pkg.srv import CountImages

    server = tutorial("count_images")
    client = observer_node.create_client(CountImages, "/count_images")
    assert client.wait_for_service(timeout_sec=30.0), server.text("err")

    folder = tmp_path / "pictures"
    folder.mkdir()
    for name in ("a.png", "b.png", "c.png", "notes.txt"):
        (folder / name).write_bytes(b"\x89PNG" if name.endswith(".png") else b"text")

    response = client.call(CountImages.Request(folder_path=str(folder)), timeout_sec=30.0)

    assert response.count == 3
    assert response.message == f"3 image(s) in {folder}"
    assert server.wait_for(re.escape(f"3 image(s) in {folder}"), "err", timeout=15.0)

    missing = tmp_path / "no_such_folder"
    response = client.call(CountImages.Request(folder_path=str(missing)), timeout_sec=30.0)

    assert response.count == 0
    assert response.message == f"not a folder: {missing}"
    assert_clean_exit(server)


@pytest.mark.slow
def test_the_timer_node_ticks_at_its_parameter_period_and_speeds_up_when_it_is_set_live(
    tutorial: Callable[..., Watched], observer_node: Node
) -> None:
    from rcl_interfaces.srv import SetParameters

    from rosl import Parameter

    node = tutorial("timer_node", "--ros-args", "-p", "timer_period_s:=0.25")
    assert node.wait_for(r"\[timer_node\]: Timer period: 0\.25 s", "err", timeout=30.0), node.text(
        "err"
    )
    assert node.wait_for(TICK, "err", timeout=30.0, count=8)  # 2 s of ticks at 4 Hz

    client = observer_node.create_client(SetParameters, "/timer_node/set_parameters")
    assert client.wait_for_service(timeout_sec=30.0)
    request = SetParameters.Request(
        parameters=[Parameter("timer_period_s", value=0.1).to_parameter_msg()]
    )
    response = client.call(request, timeout_sec=30.0)
    assert [r.successful for r in response.results] == [True]
    assert node.wait_for(PERIOD_CHANGED, "err", timeout=15.0)
    changed_at = float(node.matching(PERIOD_CHANGED, "err")[0].group(1))

    def ticks() -> list[tuple[float, int, float]]:
        return [(float(m[1]), int(m[2]), float(m[3])) for m in node.matching(TICK, "err")]

    assert wait_until(lambda: sum(1 for t in ticks() if t[0] > changed_at) >= 17, timeout=30.0)
    assert_clean_exit(node)

    every = ticks()
    before = [t for t in every if t[0] < changed_at]
    after = [t for t in every if t[0] > changed_at]
    assert [n for _, n, _ in every] == list(range(1, len(every) + 1))  # none skipped
    assert {period for _, _, period in before} == {0.25}
    assert {period for _, _, period in after} == {0.1}

    # on the node's own clock (its log stamps), so reading delays don't count. A loaded machine
    # only makes a tick late (the timer then skips to its next slot), never early: tick k comes
    # more than k - 1 periods after the first, whatever the load
    for run, period in ((before, 0.25), (after, 0.1)):
        early = [
            (k, t - run[0][0])
            for k, (t, _, _) in enumerate(run)
            if t - run[0][0] <= (k - 1) * period
        ]
        assert early == [], f"ticks earlier than their {period} s period allows: {early}"
    # and it did speed up: most gaps are one new period (a gap of the old 0.25 s would need a
    # late tick, and the timer skipping a slot, for more than half of them)
    gaps = sorted(b[0] - a[0] for a, b in itertools.pairwise(after))
    assert gaps[len(gaps) // 2] < 0.2, f"median gap {gaps[len(gaps) // 2]:.3f} s at a 0.1 s period"


EXECUTABLES = {
    "my_publisher": ((), r"Publishing: counter=1 "),
    "my_subscriber": ((), None),
    "timer_node": (("--ros-args", "-p", "timer_period_s:=0.1"), r"Tick 2 "),
    "count_images": ((), None),
}


@pytest.mark.parametrize("executable", sorted(EXECUTABLES))
def test_ctrl_c_stops_a_tutorial_node_cleanly_and_it_leaves_the_graph_at_once(
    executable: str, tutorial: Callable[..., Watched], observer_node: Node
) -> None:
    args, busy = EXECUTABLES[executable]
    child = tutorial(executable, *args)
    graph = observer_node.participant.graph
    record = wait_for_node(graph, f"/{executable}")
    if busy is not None:  # let it get going first
        assert child.wait_for(busy, "err", timeout=30.0), child.text("err")

    timing = leaving_time(graph, record.process, child.send, 3 * LEASE_S)

    assert timing is not None, f"/{executable} never left the graph"
    last_seen, gone_at = timing
    assert gone_at - last_seen < LEASE_S  # it said goodbye; its lease did not run out
    assert_clean_exit(child)
