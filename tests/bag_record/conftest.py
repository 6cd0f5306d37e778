"""Fixtures for the recording tests: a bus (domain + children) shared by a module's tests.

A module that records once and checks the bag in many tests uses ``module_bus``: a domain id
locked the same way as ``tests.conftest.domain_id`` (a lock file held for the module) and a
``Processes`` group whose children get that domain in ``ROSL_DOMAIN_ID``.
"""

from __future__ import annotations

import dataclasses
import json
import signal
from typing import TYPE_CHECKING, Any

import pytest

from tests.conftest import Processes, lock_domain

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path


class DomainProcesses(Processes):
    """``Processes`` whose children all run on one domain (``ROSL_DOMAIN_ID``)."""

    def __init__(self, domain: int) -> None:
        super().__init__()
        self.domain = domain

    def start(self, args: list[str], **kwargs: Any) -> Any:
        env = {"ROSL_DOMAIN_ID": str(self.domain), **(kwargs.pop("env", None) or {})}
        return super().start(args, env=env, **kwargs)


@pytest.fixture(scope="module")
def module_bus() -> Iterator[DomainProcesses]:
    """Children on a domain of their own for the whole module (ended by pid afterwards)."""
    domain, handle = lock_domain()
    group = DomainProcesses(domain)
    try:
        yield group
    finally:
        group.close()
        handle.close()


@pytest.fixture(scope="module")
def module_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An empty folder for a module's recordings (and its children's working directory)."""
    return tmp_path_factory.mktemp("bags")


# --- a recording with service traffic, shared by the service and info tests --------------------

SERVER = r"""
import rosl
from example_interfaces.srv import AddTwoInts

rosl.init([])
node = rosl.Node("adder")


def add(request, response):
    response.sum = request.a + request.b
    return response


node.create_service(AddTwoInts, "/add_two_ints", add)
print("READY", flush=True)
try:
    rosl.spin(node)
except KeyboardInterrupt:
    pass
"""

CLIENT = r"""
import json, sys, time
import rosl
from example_interfaces.srv import AddTwoInts

rosl.init([])
node = rosl.Node("adder_client")
client = node.create_client(AddTwoInts, "/add_two_ints")
assert client.wait_for_service(timeout_sec=30.0), "no server"
deadline = time.monotonic() + 30.0
while node.count_subscribers("/add_two_ints/_service_event") < 1:
    assert time.monotonic() < deadline, "the recorder never subscribed to the service events"
    time.sleep(0.02)
time.sleep(0.2)
for a, b in json.loads(sys.argv[1]):
    before = time.time_ns()
    response = client.call(AddTwoInts.Request(a=a, b=b), timeout_sec=10.0)
    after = time.time_ns()
    print(json.dumps({"a": a, "b": b, "sum": response.sum, "before": before, "after": after}),
          flush=True)
node.destroy_node()
rosl.shutdown()
"""

CALLS = [[2, 3], [-10, 4]]
NUMBERS = list(range(1, 6))
WORDS = ["alpha", "beta", "gamma"]


@dataclasses.dataclass
class ServiceBag:
    """A bag recorded with --include-services, and one recorded alongside without it."""

    folder: Path
    plain: Path
    calls: list[dict[str, int]]


@pytest.fixture(scope="session")
def service_bag(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceBag]:
    from tests.bag_record import support

    root = tmp_path_factory.mktemp("service_bags")
    domain, handle = lock_domain()
    group = DomainProcesses(domain)
    try:
        folder, plain = root / "with_services", root / "without_services"
        recorder = support.start_recorder(
            group, "-a", "--include-services", "-o", str(folder), cwd=root
        )
        other = support.start_recorder(group, "-a", "-o", str(plain), cwd=root)
        server = support.Child(group.python(SERVER, cwd=root))
        assert server.wait_for("^READY", timeout=30), server.both()
        support.run_publisher(
            group,
            {"node": "info_talker", "wait_subscribers": 2,
             "publishers": [{"topic": "/numbers", "type": "std_msgs/msg/Int32"},
                            {"topic": "/words", "type": "std_msgs/msg/String"}],
             "messages": [*[(0, {"data": n}) for n in NUMBERS],
                          *[(1, {"data": w}) for w in WORDS]]},
            cwd=root,
        )  # fmt: skip
        client = support.Child(group.python(CLIENT, json.dumps(CALLS), cwd=root))
        assert client.finish(60) == 0, client.both()
        calls = [json.loads(line) for line in client.lines() if line.startswith("{")]
        server.signal(signal.SIGINT, timeout=10)
        support.stop_recorder(recorder)
        support.stop_recorder(other)
        yield ServiceBag(folder, plain, calls)
    finally:
        group.close()
        handle.close()
