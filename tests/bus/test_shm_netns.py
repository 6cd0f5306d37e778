"""Shared memory stops at the network namespace: a subscriber behind a veth still gets bytes.

A process's host identity includes its network namespace, so a subscriber in another
namespace counts as another host, however much it shares with the publisher otherwise. Needs
``ip netns`` (see ``test_interface_netns.py``, whose fixture makes and deletes the spaces).
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from tests.bus import shm_snippets as snippets
from tests.bus.helpers import Lines
from tests.bus.test_interface_netns import netns, stop, veth_pair  # noqa: F401 - the fixture

if TYPE_CHECKING:
    import subprocess

    from tests.bus.test_interface_netns import Namespaces

ROUNDS = 4


def start(
    space: Namespaces, namespace: str, veth: str, code: str, *args: str
) -> tuple[subprocess.Popen[str], Lines]:
    """A Python child in ``namespace`` using ``veth``, and its output lines."""
    child = space.run(namespace, [sys.executable, "-c", code, *args], env={"ROSL_INTERFACE": veth})
    return child, Lines(child.stdout)


def talk(
    space: Namespaces, namespace: str, veth: str, wanted: int
) -> tuple[subprocess.Popen[str], list[str]]:
    """A talker of ROUNDS rounds in ``namespace``; the child and its descriptor counts."""
    child, said = start(space, namespace, veth, snippets.TALKER, str(ROUNDS), str(wanted))
    line = said.wait_line("shm ", 90.0)
    assert line is not None, (said.lines, Lines(child.stderr).rest(2.0))
    return child, line.split()[1:]


def test_a_subscriber_in_another_network_namespace_gets_the_bytes(
    netns: Namespaces,  # noqa: F811 - the fixture imported above
    domain_id: int,
) -> None:
    a, va, b, vb = veth_pair(netns)
    _, near = start(netns, a, va, snippets.LISTENER, "near_listener")
    assert near.wait_line("up", 30.0)

    # alone with a subscriber of its own namespace, the talker uses shared memory
    first, shm = talk(netns, a, va, 1)
    assert shm == [str(ROUNDS), str(ROUNDS), str(ROUNDS), "0"]
    assert near.wait_for(lambda lines: snippets.complete(lines, ROUNDS), 30.0), near.lines
    stop(first)

    # with one behind the veth too, everything goes over the wire, and both get it all
    _, far = start(netns, b, vb, snippets.LISTENER, "far_listener")
    assert far.wait_line("up", 30.0)
    near.lines.clear()
    _, shm = talk(netns, a, va, 2)
    assert shm == ["0", "0", "0", "0"]
    for listener in (near, far):
        assert listener.wait_for(lambda lines: snippets.complete(lines, ROUNDS), 60.0), (
            listener.lines
        )
        assert not snippets.bads(listener.lines)
