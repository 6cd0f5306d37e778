"""Executors run the callbacks of their own nodes, as rclpy's do.

Real nodes on the test's domain over loopback: which executor runs which node's callbacks,
one callback per ``spin_once``, callback groups (mutually exclusive, reentrant, custom),
thread pools, custom executors written against rclpy's API, coroutine callbacks, guard
conditions and waitables, keep-last queues, shutdown and removal. Every wait is bounded;
the assertions are guarantees (counts, order, never-concurrent), never speeds.
"""

from __future__ import annotations

import contextlib
import json
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, ClassVar

import pytest

from rosl.executor import (
    Executor,
    MultiThreadedExecutor,
    ShutdownException,
    SingleThreadedExecutor,
    TimeoutException,
)
from rosl.node.callback_groups import (
    CallbackGroup,
    MutuallyExclusiveCallbackGroup,
    ReentrantCallbackGroup,
)
from rosl.node.task import Future
from rosl.node.waitable import Waitable
from tests.conftest import wait_until
from tests.node.helpers import snippet
from tests.node.test_rclpy_compat import RUN_AS_RCLPY

if TYPE_CHECKING:
    from collections.abc import Callable

BOUND = 20.0  # seconds: only a broken executor takes this long


def spin_until(executor: Executor, predicate: Callable[[], bool], timeout: float = BOUND) -> bool:
    """Spin ``executor`` on this thread until ``predicate()`` or the (bounded) deadline."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() >= deadline:
            return predicate()
        executor.spin_once(timeout_sec=0.05)
    return True


def settle(executor: Executor, node: Any, startup: list[Any]) -> None:
    """Spin until the timers the node had when created (``startup``) are gone.

    A rosl node checks once, shortly after it is created, that its name is unique (a timer
    that destroys itself); tests that count every callback an executor runs let it finish
    first.
    """
    assert spin_until(executor, lambda: not any(t in node.timers for t in startup)), node.timers


def settled(ros: Any, name: str) -> tuple[Any, SingleThreadedExecutor]:
    """A new node in its own executor, spun past its start-up timers."""
    node = ros.Node(name)
    startup = list(node.timers)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    settle(executor, node, startup)
    return node, executor


class Background:
    """Spins an executor on its own thread; ``stop`` shuts it down and joins (bounded)."""

    def __init__(self, executor: Executor) -> None:
        self.executor = executor
        self.error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            with contextlib.suppress(ShutdownException):  # custom executors may let it out
                self.executor.spin()
        except BaseException as err:  # reported by stop()
            self.error = err

    def stop(self) -> None:
        self.executor.shutdown(timeout_sec=BOUND)
        self.thread.join(BOUND)
        assert not self.thread.is_alive(), "spin() did not return after shutdown()"
        if self.error is not None:
            raise self.error


def _adder(request: Any, response: Any) -> Any:
    response.sum = request.a + request.b
    return response


def _start_script(spawn: Any, tmp_path: Any, source: str, *args: str) -> Any:
    script = tmp_path / "script.py"
    script.write_text(snippet(source))
    return spawn(RUN_AS_RCLPY, str(script), *args)


# --- 1. an executor runs its own nodes only --------------------------------------------------


def test_an_executor_runs_only_the_subscriptions_timers_and_services_of_its_nodes(ros):
    from example_interfaces.srv import AddTwoInts
    from std_msgs.msg import Int32

    a, b = ros.Node("node_a"), ros.Node("node_b")
    heard: dict[str, list[int]] = {"a": [], "b": []}
    a.create_subscription(Int32, "shared", lambda m: heard["a"].append(m.data), 10)
    sub_b = b.create_subscription(Int32, "shared", lambda m: heard["b"].append(m.data), 10)
    ticks = {"a": 0, "b": 0}
    a.create_timer(0.01, lambda: ticks.__setitem__("a", ticks["a"] + 1))
    b.create_timer(0.01, lambda: ticks.__setitem__("b", ticks["b"] + 1))

    service = b.create_service(AddTwoInts, "only_b_adds", _adder)
    client = a.create_client(AddTwoInts, "only_b_adds")
    talker = ros.Node("talker")
    pub = talker.create_publisher(Int32, "shared", 10)
    executor_a, executor_b = SingleThreadedExecutor(), SingleThreadedExecutor()
    executor_a.add_node(a)
    executor_b.add_node(b)
    assert (a.executor, b.executor, talker.executor) == (executor_a, executor_b, None)

    for n in range(5):
        pub.publish(Int32(data=n))
    assert spin_until(executor_a, lambda: len(heard["a"]) == 5 and ticks["a"] >= 5), heard
    assert heard["b"] == []  # a's executor read b's messages off the socket but did not run them
    assert len(sub_b._queue) == 5
    assert ticks["b"] == 0

    assert client.wait_for_service(timeout_sec=BOUND)
    answer = client.call_async(AddTwoInts.Request(a=2, b=40))
    assert spin_until(executor_a, lambda: len(service._queue) == 1), "the request never arrived"
    assert not answer.done()
    assert service.handled == 0

    assert spin_until(
        executor_b, lambda: service.handled == 1 and len(heard["b"]) == 5 and ticks["b"] >= 1
    )
    assert heard["b"] == [0, 1, 2, 3, 4]
    assert not answer.done()  # the client is a's: its response waits for a's executor
    assert spin_until(executor_a, answer.done)
    assert answer.result().sum == 42
    assert heard["a"] == [0, 1, 2, 3, 4]


# --- 2. spin_once runs exactly one callback --------------------------------------------------


def test_each_spin_once_runs_exactly_one_callback_when_several_are_ready(ros):
    from std_msgs.msg import Int32

    node, executor = settled(ros, "one_at_a_time")
    ran: list[str] = []
    node.create_timer(0.001, lambda: ran.append("fast"))
    node.create_timer(0.002, lambda: ran.append("faster"))
    node.create_subscription(Int32, "plenty", lambda m: ran.append(f"msg {m.data}"), 100)
    pub = node.create_publisher(Int32, "plenty", 100)
    for n in range(20):
        pub.publish(Int32(data=n))
    time.sleep(0.05)  # lets both timers fall due; the check below holds whatever happens

    for call in range(1, 41):
        before = len(ran)
        executor.spin_once(timeout_sec=None)
        assert len(ran) == before + 1, f"spin_once call {call} ran {ran[before:]}"
    assert any(r.startswith("msg") for r in ran)
    assert {"fast", "faster"} <= set(ran)


def test_spin_once_with_a_timeout_and_nothing_ready_returns_without_running_anything(ros):
    from std_msgs.msg import Int32

    node, executor = settled(ros, "idle")
    ran: list[str] = []
    node.create_timer(3600.0, lambda: ran.append("timer"))
    node.create_subscription(Int32, "silence", lambda m: ran.append("message"), 10)

    returned = threading.Event()

    def once() -> None:
        executor.spin_once(timeout_sec=0.2)
        returned.set()

    worker = threading.Thread(target=once, daemon=True)
    worker.start()
    worker.join(30.0)
    assert returned.is_set(), "spin_once(timeout_sec=0.2) did not return"
    assert ran == []
    with pytest.raises(TimeoutException):
        executor.wait_for_ready_callbacks(timeout_sec=0.2)
    assert ran == []


CYCLE_TALKER = """
import time

import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int32


def main():
    rclpy.init()
    node = Node("cycle_talker")
    pub = node.create_publisher(Int32, "cycles", 10)
    sent = []

    def tick():
        sent.append(len(sent) + 1)
        pub.publish(Int32(data=sent[-1]))

    node.create_timer(0.6, tick)  # talker_qos ticks once a second: a slow timer
    deadline = time.monotonic() + 20
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    count = 0
    while count < 8:
        executor.spin_once()
        count += 1
    print(f"published {len(sent)}", flush=True)
    executor.shutdown()
    node.destroy_node()
    rclpy.shutdown()


main()
"""


def test_a_talker_looping_over_spin_once_publishes_once_per_cycle(ros, spawn, tmp_path):
    from std_msgs.msg import Int32

    listener = ros.Node("cycle_listener")
    got: list[int] = []
    listener.create_subscription(Int32, "cycles", lambda m: got.append(m.data), 100)
    executor = SingleThreadedExecutor()
    executor.add_node(listener)
    spinner = Background(executor)
    child = _start_script(spawn, tmp_path, CYCLE_TALKER)

    def graph_noise() -> None:  # nodes come and go while the talker spins: discovery traffic
        deadline = time.monotonic() + 40.0
        for n in range(10**6):
            if child.popen.poll() is not None or time.monotonic() > deadline:
                return
            passer = ros.Node(f"passer_{n}")
            passer.create_publisher(Int32, "noise", 10).publish(Int32(data=n))
            time.sleep(0.05)
            passer.destroy_node()

    noise = threading.Thread(target=graph_noise, daemon=True)
    noise.start()
    try:
        out, err = child.finish(timeout=40.0)
        noise.join(BOUND)
        assert child.returncode == 0, err
        assert out.strip().splitlines()[-1] == "published 8", out
        assert wait_until(lambda: len(got) >= 8, BOUND), (got, out)
        time.sleep(0.3)  # a ninth message, were there one, is already on its way
    finally:
        spinner.stop()
    assert got == [1, 2, 3, 4, 5, 6, 7, 8]


# --- 3. and 4. callback groups under a thread pool -------------------------------------------


class Concurrency:
    """Counts how many tracked callbacks run at once, and how often each ran."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.active = 0
        self.most = 0
        self.runs: dict[str, int] = {}
        self.threads: set[str] = set()

    def enter(self, name: str) -> None:
        with self.lock:
            self.active += 1
            self.most = max(self.most, self.active)
            self.runs[name] = self.runs.get(name, 0) + 1
            self.threads.add(threading.current_thread().name)

    def leave(self) -> None:
        with self.lock:
            self.active -= 1

    def tracked(self, name: str, pause: float) -> Callable[..., None]:
        def callback(*_: Any) -> None:
            self.enter(name)
            try:
                time.sleep(pause)
            finally:
                self.leave()

        return callback


def test_a_mutually_exclusive_group_never_runs_two_callbacks_at_once_on_four_threads(ros):
    from std_msgs.msg import Int32

    node = ros.Node("exclusive")
    group = MutuallyExclusiveCallbackGroup()
    seen = Concurrency()
    names = ["timer 1", "timer 2", "timer 3", "sub 1", "sub 2"]
    # the timers fall due together, and the work fits the period: nothing is starved
    for name in names[:3]:
        node.create_timer(0.03, seen.tracked(name, 0.003), callback_group=group)
    for n, name in enumerate(names[3:], 1):
        node.create_subscription(
            Int32, f"busy_{n}", seen.tracked(name, 0.003), 10, callback_group=group
        )
    feeder = ros.Node("feeder")
    pubs = [feeder.create_publisher(Int32, f"busy_{n}", 10) for n in (1, 2)]
    feeder.create_timer(0.03, lambda: [p.publish(Int32(data=1)) for p in pubs])
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    executor.add_node(feeder)
    spinner = Background(executor)
    try:
        done = wait_until(lambda: all(seen.runs.get(n, 0) >= 5 for n in names), BOUND)
    finally:
        spinner.stop()
    assert done, seen.runs
    assert seen.most == 1, f"{seen.most} callbacks of one mutually exclusive group ran at once"


def test_busy_timers_of_one_exclusive_group_take_turns_on_four_threads(ros):
    # each callback outlasts every period, so all three are always due when the group frees:
    # looking in the same order each time would run only the first one
    node = ros.Node("turns")
    group = MutuallyExclusiveCallbackGroup()
    seen = Concurrency()
    names = ["timer 1", "timer 2", "timer 3"]
    for name in names:
        node.create_timer(0.005, seen.tracked(name, 0.02), callback_group=group)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    spinner = Background(executor)
    try:
        done = wait_until(lambda: sum(seen.runs.get(n, 0) for n in names) >= 30, BOUND)
    finally:
        spinner.stop()
    assert done, seen.runs
    assert all(seen.runs.get(n, 0) >= 5 for n in names), f"a timer was starved: {seen.runs}"
    assert seen.most == 1


N = 4


def _barrier_callbacks(
    node: Any, group: CallbackGroup, barrier: threading.Barrier, seen: Concurrency
) -> tuple[list[Any], list[str]]:
    outcomes: list[str] = []

    def make(n: int) -> Callable[[], None]:
        def callback() -> None:
            seen.enter(f"guard {n}")
            try:
                barrier.wait()
                outcomes.append("passed")
            except threading.BrokenBarrierError:
                outcomes.append("broken")
            finally:
                seen.leave()

        return callback

    guards = [node.create_guard_condition(make(n), group) for n in range(N)]
    return guards, outcomes


def _race_to_barrier(
    node: Any, barrier: threading.Barrier, threads: int
) -> tuple[list[str], Concurrency]:
    """N reentrant callbacks wait on ``barrier`` under ``threads`` pool threads; outcomes."""
    seen = Concurrency()
    guards, outcomes = _barrier_callbacks(node, ReentrantCallbackGroup(), barrier, seen)
    executor = MultiThreadedExecutor(num_threads=threads)
    executor.add_node(node)
    spinner = Background(executor)
    try:
        for guard in guards:
            guard.trigger()
        assert wait_until(lambda: len(outcomes) == N, 40.0), outcomes
    finally:
        spinner.stop()
    return outcomes, seen


def test_a_reentrant_group_runs_n_callbacks_at_once_on_n_threads(ros):
    barrier = threading.Barrier(N, timeout=30.0)  # passes only when N callbacks wait at once
    outcomes, seen = _race_to_barrier(ros.Node("reentrant"), barrier, N)
    assert outcomes == ["passed"] * N
    assert seen.most == N
    assert len(seen.threads) == N


def test_a_pool_of_fewer_threads_never_runs_more_callbacks_at_once(ros):
    barrier = threading.Barrier(N, timeout=3.0)  # needs N at once: N - 1 threads cannot
    outcomes, seen = _race_to_barrier(ros.Node("short_handed"), barrier, N - 1)
    assert outcomes == ["broken"] * N
    assert barrier.broken
    assert seen.most <= N - 1
    assert len(seen.threads) <= N - 1


# --- 5. a custom callback group --------------------------------------------------------------


class TokenGroup(CallbackGroup):
    """Grants a fixed number of runs and never refills (a token bucket without a refill)."""

    def __init__(self, tokens: int) -> None:
        super().__init__()
        self.tokens = tokens
        self.lock = threading.Lock()
        self.began = 0
        self.ended = 0

    def can_execute(self, entity: Any) -> bool:
        with self.lock:
            return self.tokens > 0

    def beginning_execution(self, entity: Any) -> bool:
        with self.lock:
            if self.tokens <= 0:
                return False
            self.tokens -= 1
            self.began += 1
            return True

    def ending_execution(self, entity: Any) -> None:
        with self.lock:
            self.ended += 1


@pytest.mark.parametrize("kind", [SingleThreadedExecutor, MultiThreadedExecutor])
def test_a_custom_callback_group_decides_how_often_its_timer_runs(ros, kind):
    node = ros.Node("throttled")
    group = TokenGroup(tokens=5)
    runs = {"throttled": 0, "free": 0}
    node.create_timer(0.002, lambda: runs.__setitem__("throttled", runs["throttled"] + 1), group)
    node.create_timer(0.002, lambda: runs.__setitem__("free", runs["free"] + 1))
    executor = kind()
    executor.add_node(node)
    spinner = Background(executor)
    try:
        # the free timer keeps running long after the tokens are spent
        assert wait_until(lambda: runs["free"] >= 50 and runs["throttled"] >= 5, BOUND), runs
    finally:
        spinner.stop()
    assert runs["throttled"] == 5
    assert group.began == group.ended == 5
    assert group.has_entity(node.timers[-2])


# --- 6. a custom executor written against rclpy's API ----------------------------------------


class PriorityExecutor(Executor):
    """Runs the callbacks of urgent nodes on one pool, everything else on another."""

    def __init__(self, urgent: list[Any], style: str) -> None:
        super().__init__()
        self.urgent = set(urgent)
        self.style = style
        self.fast_lane = ThreadPoolExecutor(2, thread_name_prefix="urgent")
        self.slow_lane = ThreadPoolExecutor(1, thread_name_prefix="ordinary")

    def spin_once(self, timeout_sec: float | None = None) -> None:
        if self.style == "generator":  # how executors for older rclpy were written
            try:
                handler, _group, node = next(self.wait_for_ready_callbacks(timeout_sec=timeout_sec))
            except StopIteration:
                return
        else:
            try:
                handler, _group, node = self.wait_for_ready_callbacks(timeout_sec=timeout_sec)
            except (TimeoutException, ShutdownException):
                return
        lane = self.fast_lane if node in self.urgent else self.slow_lane
        lane.submit(handler)

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        finished = super().shutdown(timeout_sec)
        self.fast_lane.shutdown(wait=True)
        self.slow_lane.shutdown(wait=True)
        return finished


@pytest.mark.parametrize("style", ["tuple", "generator"])
def test_a_custom_executor_hands_each_nodes_callbacks_to_its_own_pool(ros, style):
    from std_msgs.msg import Int32

    where: dict[str, set[str]] = {}
    counts: dict[str, int] = {}

    def record(what: str) -> Callable[..., None]:
        def callback(*_: Any) -> None:
            where.setdefault(what, set()).add(threading.current_thread().name)
            counts[what] = counts.get(what, 0) + 1

        return callback

    urgent, ordinary = ros.Node("urgent"), ros.Node("ordinary")
    to_urgent = ordinary.create_publisher(Int32, "to_urgent", 10)
    to_ordinary = urgent.create_publisher(Int32, "to_ordinary", 10)
    urgent.create_subscription(Int32, "to_urgent", record("urgent message"), 10)
    ordinary.create_subscription(Int32, "to_ordinary", record("ordinary message"), 10)
    urgent.create_timer(0.02, lambda: (record("urgent timer")(), to_ordinary.publish(Int32())))
    ordinary.create_timer(0.02, lambda: (record("ordinary timer")(), to_urgent.publish(Int32())))
    executor = PriorityExecutor([urgent], style)
    executor.add_node(urgent)
    executor.add_node(ordinary)
    spinner = Background(executor)
    kinds = ["urgent message", "ordinary message", "urgent timer", "ordinary timer"]
    try:
        done = wait_until(lambda: all(counts.get(k, 0) >= 3 for k in kinds), BOUND)
    finally:
        spinner.stop()
    assert done, counts
    for kind in kinds:
        prefix = kind.split()[0]
        assert all(name.startswith(f"{prefix}_") for name in where[kind]), (kind, where)


PRIORITY_SCRIPT = """
import json
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import rclpy
from rclpy.executors import Executor, ShutdownException, TimeoutException
from rclpy.node import Node


class TwoLanes(Executor):
    def __init__(self, urgent):
        super().__init__()
        self.urgent = urgent
        self.lanes = {
            True: ThreadPoolExecutor(1, thread_name_prefix="urgent"),
            False: ThreadPoolExecutor(1, thread_name_prefix="ordinary"),
        }

    def spin_once(self, timeout_sec=None):
        try:
            handler, group, node = self.wait_for_ready_callbacks(timeout_sec=timeout_sec)
        except (TimeoutException, ShutdownException):
            return
        self.lanes[node is self.urgent].submit(handler)


def main():
    rclpy.init()
    fast, slow = Node("fast"), Node("slow")
    where = {"fast": set(), "slow": set()}
    for node in (fast, slow):
        node.create_timer(0.02, lambda n=node.get_name(): where[n].add(threading.current_thread().name))
    executor = TwoLanes(fast)
    executor.add_node(fast)
    executor.add_node(slow)
    deadline = time.monotonic() + 20
    while not all(where.values()) and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)
    executor.shutdown()
    for lane in executor.lanes.values():
        lane.shutdown()
    print(json.dumps({k: sorted(v) for k, v in where.items()}), flush=True)
    rclpy.shutdown()


main()
"""


def test_an_rclpy_script_subclassing_executor_runs_its_nodes_on_its_pools(spawn, tmp_path):
    child = _start_script(spawn, tmp_path, PRIORITY_SCRIPT)
    out, err = child.finish(timeout=40.0)
    assert child.returncode == 0, err
    where = json.loads(out.strip().splitlines()[-1])
    assert where["fast"], where
    assert where["slow"], where
    assert all(name.startswith("urgent_") for name in where["fast"]), where
    assert all(name.startswith("ordinary_") for name in where["slow"]), where


# --- 7. coroutine callbacks ------------------------------------------------------------------

SERVER = """
import sys
import time

import rosl
from example_interfaces.srv import AddTwoInts
from std_msgs.msg import Int32

rosl.init()
node = rosl.Node("adder")
side = node.create_publisher(Int32, "meanwhile", 10)


def add(request, response):
    for n in range(int(sys.argv[1])):  # messages sent while the caller waits for the answer
        side.publish(Int32(data=n))
    time.sleep(0.2 if int(sys.argv[1]) else 0.0)
    response.sum = request.a + request.b
    print("served", request.a, request.b, flush=True)
    return response


node.create_service(AddTwoInts, "add_two_ints", add)
print("ready", flush=True)
rosl.spin(node)
"""


def test_an_async_timer_awaits_a_service_of_a_node_in_the_same_executor(ros):
    from example_interfaces.srv import AddTwoInts

    server = ros.Node("local_adder")
    server.create_service(AddTwoInts, "local_add", _adder)
    caller = ros.Node("async_caller")
    client = caller.create_client(AddTwoInts, "local_add")  # the node's default group
    results: list[int] = []

    async def once() -> None:
        timer.cancel()
        response = await client.call_async(AddTwoInts.Request(a=40, b=2))
        results.append(response.sum)

    timer = caller.create_timer(0.01, once)  # the same default (mutually exclusive) group
    assert client.callback_group is timer.callback_group is caller.default_callback_group
    assert client.wait_for_service(timeout_sec=BOUND)
    executor = SingleThreadedExecutor()
    executor.add_node(server)
    executor.add_node(caller)
    try:
        assert spin_until(executor, lambda: bool(results)), "the awaited call never ended"
    finally:
        executor.shutdown(timeout_sec=2.0)  # a stuck coroutine would hold it
    assert results == [42]


def test_an_async_subscription_callback_awaits_a_service_in_another_process(ros, spawn):
    from example_interfaces.srv import AddTwoInts
    from std_msgs.msg import Int32

    child = spawn(SERVER, "0")
    child.expect("^ready$")
    node = ros.Node("async_listener")
    client = node.create_client(AddTwoInts, "add_two_ints")
    results: list[tuple[int, int]] = []

    async def on_message(msg: Any) -> None:
        response = await client.call_async(AddTwoInts.Request(a=msg.data, b=100))
        results.append((msg.data, response.sum))

    node.create_subscription(Int32, "numbers", on_message, 10)
    pub = node.create_publisher(Int32, "numbers", 10)
    assert client.wait_for_service(timeout_sec=BOUND)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        for n in (1, 2, 3):
            pub.publish(Int32(data=n))
        assert spin_until(executor, lambda: len(results) == 3), results
    finally:
        executor.shutdown(timeout_sec=2.0)  # a stuck coroutine would hold it
    assert results == [(1, 101), (2, 102), (3, 103)]


def test_an_async_service_callback_answers_after_awaiting(ros):
    from example_interfaces.srv import AddTwoInts

    server = ros.Node("slow_adder")
    executor = SingleThreadedExecutor()
    waiting: list[tuple[Future[int], int]] = []

    async def add_later(request: Any, response: Any) -> Any:
        later = executor.create_future()
        waiting.append((later, request.a * 10))
        response.sum = await later + request.b  # completed by the timer, a callback later
        return response

    def complete() -> None:
        while waiting:
            later, value = waiting.pop()
            later.set_result(value)

    server.create_service(AddTwoInts, "add_later", add_later)
    server.create_timer(0.01, complete, MutuallyExclusiveCallbackGroup())
    executor.add_node(server)
    caller = ros.Node("plain_caller")  # no executor: Client.call waits for its own answer
    client = caller.create_client(AddTwoInts, "add_later")
    spinner = Background(executor)
    try:
        assert client.wait_for_service(timeout_sec=BOUND)
        answer = client.call(AddTwoInts.Request(a=4, b=2), timeout_sec=BOUND)
    finally:
        spinner.stop()
    assert answer.sum == 42


def test_create_task_runs_a_coroutine_function_to_completion(ros):
    node = ros.Node("tasker")
    gate: Future[int] = Future()
    node.create_timer(0.01, lambda: None if gate.done() else gate.set_result(5))

    async def work(a: int, b: int) -> int:
        extra = await gate
        return a + b + extra

    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        task = executor.create_task(work, 20, 17)
        executor.spin_until_future_complete(task, timeout_sec=BOUND)
        plain = executor.create_task(lambda: "plain")
        executor.spin_until_future_complete(plain, timeout_sec=BOUND)
    finally:
        executor.shutdown(timeout_sec=BOUND)
    assert task.done()
    assert task.result() == 42
    assert plain.result() == "plain"


def test_tasks_created_together_all_run_when_spinning_until_the_first_completes(ros):
    node = ros.Node("many_tasks")
    node.create_timer(0.005, lambda: None)  # spin_once always has something to run
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        first = executor.create_task(lambda: "first")
        second = executor.create_task(lambda: "second")
        executor.spin_until_future_complete(first, timeout_sec=BOUND)
        for _ in range(20):  # a scheduled task is offered before the timer
            if second.done():
                break
            executor.spin_once(timeout_sec=BOUND)
    finally:
        executor.shutdown(timeout_sec=BOUND)
    assert first.result() == "first"
    assert second.result() == "second"


# --- 8. Client.call inside a callback --------------------------------------------------------


def test_client_call_inside_a_subscription_callback_answers_and_loses_no_message(ros, spawn):
    from example_interfaces.srv import AddTwoInts
    from std_msgs.msg import Int32

    child = spawn(SERVER, "5")
    child.expect("^ready$")
    node = ros.Node("calling_listener")
    client = node.create_client(AddTwoInts, "add_two_ints")
    events: list[str] = []

    def on_trigger(msg: Any) -> None:
        events.append("call")
        answer = client.call(AddTwoInts.Request(a=msg.data, b=1), timeout_sec=BOUND)
        events.append(f"answer {answer.sum}")

    node.create_subscription(Int32, "trigger", on_trigger, 10)
    node.create_subscription(Int32, "meanwhile", lambda m: events.append(f"side {m.data}"), 10)
    pub = node.create_publisher(Int32, "trigger", 10)
    assert client.wait_for_service(timeout_sec=BOUND)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        pub.publish(Int32(data=41))
        assert spin_until(executor, lambda: len(events) >= 7), events
    finally:
        executor.shutdown(timeout_sec=BOUND)
    assert events == ["call", "answer 42", *[f"side {n}" for n in range(5)]]
    child.expect("^served 41 1$")


# --- 9. guard conditions and waitables -------------------------------------------------------


def test_a_guard_condition_triggered_by_another_thread_wakes_a_blocked_spin_once(ros):
    node, executor = settled(ros, "guarded")
    ran: list[str] = []
    guard = node.create_guard_condition(lambda: ran.append(threading.current_thread().name))
    spinning = threading.Thread(target=executor.spin_once, name="spinner", daemon=True)
    spinning.start()
    spinning.join(0.3)
    assert spinning.is_alive(), "spin_once(timeout_sec=None) returned with nothing ready"
    assert ran == []

    threading.Thread(target=guard.trigger, daemon=True).start()
    spinning.join(30.0)
    assert not spinning.is_alive(), "a trigger from another thread did not wake spin_once"
    assert ran == ["spinner"]


def test_two_triggers_before_the_executor_looks_run_the_callback_once_or_twice(ros):
    node = ros.Node("twice")
    ran: list[int] = []
    guard = node.create_guard_condition(lambda: ran.append(1))
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    guard.trigger()
    guard.trigger()
    assert spin_until(executor, lambda: bool(ran))
    for _ in range(5):
        executor.spin_once(timeout_sec=0.05)
    assert 1 <= len(ran) <= 2


class Mailbox(Waitable):
    """A waitable that is ready while letters wait; ``post`` may be called from any thread."""

    def __init__(self, group: CallbackGroup | None) -> None:
        super().__init__(group)
        self.letters: list[str] = []
        self.lock = threading.Lock()
        self.read: list[tuple[str, str]] = []

    def post(self, letter: str) -> None:
        with self.lock:
            self.letters.append(letter)
        self.wake()

    def is_ready(self, wait_set: Any) -> bool:
        with self.lock:
            return bool(self.letters)

    def take_data(self) -> Any:
        with self.lock:
            return self.letters.pop(0)

    async def execute(self, taken_data: Any) -> None:
        self.read.append((taken_data, threading.current_thread().name))


def test_a_waitable_made_ready_by_another_thread_runs(ros):
    node, executor = settled(ros, "post_office")
    box = Mailbox(None)
    node.add_waitable(box)
    spinning = threading.Thread(target=executor.spin_once, name="spinner", daemon=True)
    spinning.start()
    spinning.join(0.3)
    assert spinning.is_alive(), "spin_once(timeout_sec=None) returned with nothing ready"
    threading.Thread(target=box.post, args=("first",), daemon=True).start()
    spinning.join(30.0)
    assert not spinning.is_alive(), "the waitable did not wake spin_once"
    assert box.read == [("first", "spinner")]

    for letter in ("second", "third"):
        box.post(letter)
    assert spin_until(executor, lambda: len(box.read) == 3), box.read
    assert [letter for letter, _ in box.read] == ["first", "second", "third"]


def test_a_fast_timer_between_its_ticks_lets_guards_waitables_and_messages_through(ros):
    # between two ticks of a fast timer the executor looks at the timers alone when nothing
    # else announced a change: a guard, a waitable and messages must announce theirs
    node, executor = settled(ros, "busy_ticker")
    ticks: list[int] = []
    node.create_timer(0.001, lambda: ticks.append(1))
    guarded: list[int] = []
    guard = node.create_guard_condition(lambda: guarded.append(1))
    box = Mailbox(None)
    node.add_waitable(box)
    from rosl.idl.registry import get_message_class

    String = get_message_class("std_msgs/msg/String")
    heard: list[str] = []
    node.create_subscription(String, "/between_ticks", lambda m: heard.append(m.data), 100)
    talker = node.create_publisher(String, "/between_ticks", 100)
    assert spin_until(executor, lambda: len(ticks) >= 20)
    threading.Thread(target=guard.trigger, daemon=True).start()
    threading.Thread(target=box.post, args=("letter",), daemon=True).start()
    assert spin_until(executor, lambda: bool(guarded) and bool(box.read)), (guarded, box.read)
    for i in range(5):
        threading.Thread(target=talker.publish, args=(String(data=f"m{i}"),)).start()
        assert spin_until(executor, lambda i=i: len(heard) > i), heard
    assert sorted(heard) == [f"m{i}" for i in range(5)]
    before = len(ticks)
    assert spin_until(executor, lambda: len(ticks) >= before + 20)  # it still ticks


def spin_some_until(executor: Executor, predicate: Callable[[], bool]) -> bool:
    """Call ``spin_some()`` (no wait) until ``predicate()`` or the (bounded) deadline."""
    deadline = time.monotonic() + BOUND
    while not predicate():
        if time.monotonic() >= deadline:
            return predicate()
        executor.spin_some()
        time.sleep(0.001)
    return True


def test_spin_some_after_looks_that_found_nothing_still_runs_whatever_comes(ros):
    # a spin_some that found nothing is remembered: until something announces a change, the
    # next ones look only at the transport and the timers (the simulator calls it once a
    # millisecond); messages, a guard, a task and a timer that falls due must all still run
    from rosl.idl.registry import get_message_class

    node, executor = settled(ros, "quiet_looker")
    String = get_message_class("std_msgs/msg/String")
    heard: list[str] = []
    node.create_subscription(String, "/after_quiet", lambda m: heard.append(m.data), 100)
    talker = ros.Node("quiet_talker").create_publisher(String, "/after_quiet", 100)
    guarded: list[int] = []
    guard = node.create_guard_condition(lambda: guarded.append(1))
    for _ in range(5):  # looks that find nothing (unless this machine took a second for them)
        executor.spin_some()
    for i in range(5):
        threading.Thread(target=talker.publish, args=(String(data=f"m{i}"),)).start()
        assert spin_some_until(executor, lambda i=i: len(heard) > i), heard
        executor.spin_some()
    assert heard == [f"m{i}" for i in range(5)]
    threading.Thread(target=guard.trigger, daemon=True).start()
    assert spin_some_until(executor, lambda: bool(guarded))
    done: list[int] = []
    executor.spin_some()
    executor.create_task(lambda: done.append(1))
    assert spin_some_until(executor, lambda: bool(done))
    ticks: list[int] = []
    node.create_timer(1.0, lambda: ticks.append(1))  # (no timer before: none looks for them)
    assert spin_some_until(executor, lambda: bool(ticks))  # due a second after it was made
    assert guarded == [1]
    assert done == [1]


def test_a_guard_triggered_while_spin_once_waits_for_a_distant_timer_runs_first(ros):
    # the wait ends at the change, and the look after it is not the timers-only one
    node, executor = settled(ros, "distant_timer")
    ticks: list[int] = []
    node.create_timer(3 * BOUND, lambda: ticks.append(1))
    guarded: list[str] = []
    guard = node.create_guard_condition(lambda: guarded.append(threading.current_thread().name))
    for round_ in range(3):  # also after waits that ended at a timeout (spin_once(0.05))
        spinning = threading.Thread(target=executor.spin_once, name="spinner", daemon=True)
        spinning.start()
        spinning.join(0.2)
        assert spinning.is_alive(), "spin_once(timeout_sec=None) returned with nothing ready"
        threading.Thread(target=guard.trigger, daemon=True).start()
        spinning.join(BOUND)
        assert not spinning.is_alive(), "the trigger did not get the guard run before the timer"
        assert guarded == ["spinner"] * (round_ + 1)
        executor.spin_once(timeout_sec=0.05)
    assert ticks == []


def test_what_a_timer_callback_makes_ready_runs_before_the_next_tick(ros):
    # a timer handed out by the timers-only look ends without telling anyone (nobody else
    # waits): what its own callback made ready must still be seen by the next look (the
    # message comes back through the bus, so only its arrival is checked)
    node, executor = settled(ros, "ticker_that_triggers")
    order: list[str] = []
    guard = node.create_guard_condition(lambda: order.append("guard"))
    from rosl.idl.registry import get_message_class

    String = get_message_class("std_msgs/msg/String")
    node.create_subscription(String, "/from_a_tick", lambda m: order.append(m.data), 10)
    talker = node.create_publisher(String, "/from_a_tick", 10)

    def tick() -> None:
        order.append("tick")
        if order.count("tick") == 3:  # by then the looks are timers-only ones
            guard.trigger()
            talker.publish(String(data="message"))

    node.create_timer(0.05, tick)
    assert spin_until(executor, lambda: "guard" in order and "message" in order), order
    third = [i for i, what in enumerate(order) if what == "tick"][2]
    assert order[third + 1] == "guard", order  # before the next tick (50 ms later)


def test_a_timer_that_spins_inside_its_callback_does_not_starve_its_groups_subscription(ros):
    # the nested spin looks while the timer holds the group and passes over the message;
    # the timer's end must then make the next look a whole one (review)
    node, executor = settled(ros, "nested_spinner")
    from rosl.idl.registry import get_message_class

    String = get_message_class("std_msgs/msg/String")
    heard: list[str] = []
    node.create_subscription(String, "/nested_spin", lambda m: heard.append(m.data), 10)
    talker = node.create_publisher(String, "/nested_spin", 10)
    ticks: list[int] = []

    def tick() -> None:
        ticks.append(1)
        talker.publish(String(data=f"m{len(ticks)}"))
        executor.spin_once(timeout_sec=0.05)  # e.g. waiting a little for an answer

    node.create_timer(0.1, tick)
    assert spin_until(executor, lambda: len(heard) >= 5), (len(ticks), heard)


def test_timers_of_one_exclusive_group_keep_ticking_on_threads(ros):
    # on a pool, a timer ends on another thread than the one that looked: the end must wake
    # it, or a timer of the same group skipped as busy would wait for nothing
    node = ros.Node("shared_group_ticks")
    group = MutuallyExclusiveCallbackGroup()
    runs = {"a": 0, "b": 0}

    def counter(name: str) -> Callable[[], None]:
        def count() -> None:
            runs[name] += 1

        return count

    node.create_timer(0.01, counter("a"), callback_group=group)
    node.create_timer(0.01, counter("b"), callback_group=group)
    executor = MultiThreadedExecutor(num_threads=2)
    executor.add_node(node)
    spinner = Background(executor)
    try:
        done = wait_until(lambda: min(runs.values()) >= 20, BOUND)
    finally:
        spinner.stop()
    assert done, runs


def test_a_wait_given_a_change_count_ends_false_at_its_timeout_without_asking_ready(ros):
    participant = ros.Node("waiter").participant
    asked: list[int] = []

    def ready() -> bool:
        asked.append(1)
        return True

    # (discovery may change something meanwhile: then that wait ends True; most end quiet)
    ends = [participant.wait(ready, 0.02, participant.changes) for _ in range(20)]
    assert False in ends
    since = participant.changes
    participant.notify()
    assert participant.wait(ready, BOUND, since) is True
    assert asked == [], "the caller looks itself when it passes `since`"
    assert participant.wait(ready, 0.02) is True
    assert asked, "without `since` the wait asks ready()"


# --- 10. rclpy's submodules after `import rclpy` ---------------------------------------------

SUBMODULES_SCRIPT = """
import json

import rclpy

rclpy.init()
node = rclpy.create_node("submodules")
group = rclpy.callback_groups.ReentrantCallbackGroup()
finished = rclpy.task.Future()
node.create_timer(0.01, lambda: finished.done() or finished.set_result("ticked"), group)
executor = rclpy.executors.MultiThreadedExecutor(num_threads=2)
executor.add_node(node)
executor.spin_until_future_complete(finished, timeout_sec=20)
import rosl.executor, rosl.node.callback_groups, rosl.node.task
print(json.dumps({
    "result": finished.result(),
    "executor": rclpy.executors.MultiThreadedExecutor is rosl.executor.MultiThreadedExecutor,
    "group": rclpy.callback_groups.ReentrantCallbackGroup
    is rosl.node.callback_groups.ReentrantCallbackGroup,
    "future": rclpy.task.Future is rosl.node.task.Future,
}), flush=True)
executor.shutdown()
rclpy.shutdown()
"""


def test_rclpy_executors_callback_groups_and_task_are_reachable_after_import_rclpy(spawn, tmp_path):
    child = _start_script(spawn, tmp_path, SUBMODULES_SCRIPT)
    out, err = child.finish(timeout=40.0)
    assert child.returncode == 0, err
    assert json.loads(out.strip().splitlines()[-1]) == {
        "result": "ticked",
        "executor": True,
        "group": True,
        "future": True,
    }


# --- 11. keep-last queues --------------------------------------------------------------------


def test_a_subscription_not_spun_keeps_only_its_depth_of_the_latest_messages(ros):
    from std_msgs.msg import Int32

    reader = ros.Node("slow_reader")
    got: dict[int, list[int]] = {3: [], 10: []}
    subs = {
        depth: reader.create_subscription(
            Int32, "burst", lambda m, d=depth: got[d].append(m.data), depth
        )
        for depth in (3, 10)
    }
    talker = ros.Node("burst_talker")
    pub = talker.create_publisher(Int32, "burst", 10)
    for n in range(10):
        pub.publish(Int32(data=n))

    def all_arrived() -> bool:
        reader.participant.poll(0.05)  # reads the socket into the queues; runs no callback
        return all(len(s._queue) + s.dropped == 10 for s in subs.values())

    assert wait_until(all_arrived, BOUND, 0.0), {d: len(s._queue) for d, s in subs.items()}
    assert got == {3: [], 10: []}
    executor = SingleThreadedExecutor()
    executor.add_node(reader)
    try:
        assert spin_until(executor, lambda: len(got[3]) == 3 and len(got[10]) == 10), got
    finally:
        executor.shutdown(timeout_sec=BOUND)
    assert got[3] == [7, 8, 9]
    assert subs[3].dropped == 7
    assert got[10] == list(range(10))
    assert subs[10].dropped == 0


# --- 12. shutdown and remove_node ------------------------------------------------------------


@pytest.mark.parametrize("kind", [SingleThreadedExecutor, MultiThreadedExecutor])
def test_shutdown_makes_spin_in_another_thread_return(ros, kind):
    node = ros.Node("stoppable")
    ticks: list[int] = []
    node.create_timer(0.01, lambda: ticks.append(1))
    executor = kind()
    executor.add_node(node)
    spinning = threading.Thread(target=executor.spin, daemon=True)
    spinning.start()
    assert wait_until(lambda: len(ticks) >= 3, BOUND)
    assert executor.shutdown(timeout_sec=BOUND)
    spinning.join(BOUND)
    assert not spinning.is_alive(), "spin() kept running after shutdown()"
    assert executor.get_nodes() == []
    assert node.executor is None


def test_a_removed_node_has_no_more_callbacks_run(ros):
    from std_msgs.msg import Int32

    gone, staying = ros.Node("gone"), ros.Node("staying")
    counts = {"gone": 0, "gone msg": 0, "staying": 0}

    def count(key: str) -> Callable[..., None]:
        return lambda *_: counts.__setitem__(key, counts[key] + 1)

    gone.create_timer(0.005, count("gone"))
    gone.create_subscription(Int32, "still_sent", count("gone msg"), 10)
    staying.create_timer(0.005, count("staying"))
    pub = staying.create_publisher(Int32, "still_sent", 10)
    staying.create_timer(0.005, lambda: pub.publish(Int32()))
    executor = SingleThreadedExecutor()
    executor.add_node(gone)
    executor.add_node(staying)
    assert spin_until(executor, lambda: counts["gone"] >= 3 and counts["gone msg"] >= 3)

    executor.remove_node(gone)
    assert gone.executor is None
    assert executor.get_nodes() == [staying]
    # what was already handed out before the removal may still run once per entity
    after_removal = dict(counts)
    mark = counts["staying"]
    assert spin_until(executor, lambda: counts["staying"] >= mark + 5)
    assert counts["gone"] - after_removal["gone"] <= 1
    assert counts["gone msg"] - after_removal["gone msg"] <= 1
    settled = dict(counts)
    mark = counts["staying"]
    assert spin_until(executor, lambda: counts["staying"] >= mark + 20)
    executor.shutdown(timeout_sec=BOUND)
    assert counts["gone"] == settled["gone"]
    assert counts["gone msg"] == settled["gone msg"]
    assert len(gone.subscriptions[0]._queue) > 0  # its messages still arrive, unhandled


# --- review findings ----------------------------------------------------------------------


def test_threads_calling_a_service_while_a_multithreaded_executor_spins_all_get_answers(ros):
    # rclpy's usual pattern: spin in the background, call from other threads
    from example_interfaces.srv import AddTwoInts

    server = ros.Node("threads_server")
    server.create_service(AddTwoInts, "threads_add", _adder)
    asker = ros.Node("threads_asker")
    client = asker.create_client(AddTwoInts, "threads_add")
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(server)
    executor.add_node(asker)
    spinner = Background(executor)
    answers: list[int] = []
    failures: list[BaseException] = []

    def calls(offset: int) -> None:
        try:
            for n in range(50):
                answers.append(client.call(AddTwoInts.Request(a=offset, b=n), BOUND).sum)
        except BaseException as err:
            failures.append(err)

    try:
        assert client.wait_for_service(BOUND)
        threads = [threading.Thread(target=calls, args=(k * 1000,)) for k in range(3)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(4 * BOUND)
        assert not any(t.is_alive() for t in threads), "a client.call never returned"
    finally:
        spinner.stop()
    assert failures == []
    assert sorted(answers) == sorted(k * 1000 + n for k in range(3) for n in range(50))


def test_shutdown_called_from_a_callback_ends_spin(ros):
    node, executor = settled(ros, "self_stopping")
    results: list[bool] = []
    node.create_timer(0.01, lambda: results.append(executor.shutdown()))
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    spinner.join(BOUND)
    assert not spinner.is_alive(), "spin() did not return after shutdown() from a callback"
    assert results == [True]


def test_spin_until_future_complete_with_timeout_zero_still_spins_once(ros):
    node, executor = settled(ros, "zero_timeout")
    future: Future[int] = Future()
    node.create_timer(0.001, lambda: future.set_result(42))
    assert wait_until(lambda: node.timers[-1].is_ready(), BOUND)
    executor.spin_until_future_complete(future, timeout_sec=0)
    assert future.done()
    assert future.result() == 42


def test_a_node_removed_between_spins_runs_nothing_already_found(ros):
    a = ros.Node("removed_a")
    b = ros.Node("kept_b")
    ran: list[str] = []
    a.create_timer(0.001, lambda: ran.append("a1"))
    a.create_timer(0.001, lambda: ran.append("a2"))
    executor = SingleThreadedExecutor()
    executor.add_node(a)
    executor.add_node(b)
    assert wait_until(lambda: all(t.is_ready() for t in a.timers[-2:]), BOUND)
    executor.spin_once(timeout_sec=BOUND)  # one look finds both timers; one of them runs
    assert len(ran) == 1
    executor.remove_node(a)
    b.create_timer(0.001, lambda: ran.append("b"))
    executor.spin_once(timeout_sec=BOUND)
    assert ran[1:] == ["b"], ran


def test_a_thread_count_below_one_is_refused_as_a_user_error(ros):
    from rosl.errors import RoslError  # rosl run reports these in one line, no traceback

    with pytest.raises(RoslError, match=r"num_threads >= 1, got 0"):
        MultiThreadedExecutor(num_threads=0)


def test_an_asyncio_task_can_await_a_service_future_while_another_task_spins(ros):
    import asyncio

    from example_interfaces.srv import AddTwoInts

    server = ros.Node("adder")
    server.create_service(
        AddTwoInts, "add", lambda req, res: setattr(res, "sum", req.a + req.b) or res
    )
    caller = ros.Node("caller")
    client = caller.create_client(AddTwoInts, "add")
    assert client.wait_for_service(timeout_sec=20.0)
    executor = ros.SingleThreadedExecutor()
    executor.add_node(server)
    executor.add_node(caller)

    async def spinning():
        while True:
            executor.spin_once(timeout_sec=0.01)
            await asyncio.sleep(0.001)

    async def call():
        return await client.call_async(AddTwoInts.Request(a=40, b=2))

    async def run():
        spinner = asyncio.get_running_loop().create_task(spinning())
        try:
            return await asyncio.wait_for(call(), timeout=20.0)
        finally:
            spinner.cancel()

    assert asyncio.run(run()).sum == 42


def test_spin_once_of_a_node_that_waits_for_its_timers_still_runs_whatever_comes(ros):
    # after a wait that ended at its timeout, spin_once takes the timers-only way: a look at
    # the timers and a poll, no more; a message, a guard, a task, a new timer, a canceled one
    # and a timer callback that raises must all go as on the usual way
    from rosl.idl.registry import get_message_class

    node, executor = settled(ros, "timers_only")
    String = get_message_class("std_msgs/msg/String")
    ticks: list[int] = []
    node.create_timer(0.002, lambda: ticks.append(1))
    assert spin_until(executor, lambda: len(ticks) >= 20)
    assert executor._quiet is not None  # (the way under test was taken)
    heard: list[str] = []
    node.create_subscription(String, "/timers_only", lambda m: heard.append(m.data), 100)
    talker = ros.Node("timers_only_talker").create_publisher(String, "/timers_only", 100)
    for i in range(5):
        threading.Thread(target=talker.publish, args=(String(data=f"m{i}"),)).start()
        assert spin_until(executor, lambda i=i: len(heard) > i), heard
    assert heard == [f"m{i}" for i in range(5)]
    guarded: list[int] = []
    guard = node.create_guard_condition(lambda: guarded.append(1))
    assert spin_until(executor, lambda: len(ticks) >= 40)
    threading.Thread(target=guard.trigger, daemon=True).start()
    assert spin_until(executor, lambda: bool(guarded))
    done: list[int] = []
    assert spin_until(executor, lambda: len(ticks) >= 60)
    executor.create_task(lambda: done.append(1))
    assert spin_until(executor, lambda: bool(done))
    other: list[int] = []
    second = node.create_timer(0.003, lambda: other.append(1))
    assert spin_until(executor, lambda: len(other) >= 5)
    second.cancel()
    stopped_at = len(other)
    failing = node.create_timer(0.002, lambda: 1 / 0)
    before = len(ticks)
    assert spin_until(executor, lambda: len(ticks) >= before + 30)  # the error is logged
    failing.cancel()
    assert len(other) == stopped_at
    assert guarded == [1]
    assert done == [1]


def test_spin_once_with_only_a_distant_timer_returns_at_its_timeout_having_run_nothing(ros):
    node, executor = settled(ros, "distant_only")
    ticks: list[int] = []
    node.create_timer(3 * BOUND, lambda: ticks.append(1))
    for _ in range(
        4
    ):  # the first waits end at the timeout; the later ones take the timers-only way
        finished = threading.Event()

        def spin(finished: threading.Event = finished) -> None:
            executor.spin_once(timeout_sec=0.01)
            finished.set()

        threading.Thread(target=spin, daemon=True).start()
        assert finished.wait(BOUND)
    assert executor._quiet is not None
    executor.spin_once(timeout_sec=0)
    assert ticks == []


def test_spin_once_of_a_node_with_one_steady_clock_timer_ticks_and_stops_when_canceled(ros):
    from rosl.node.clock import Clock, ClockType

    node, executor = settled(ros, "one_steady_timer")
    ticks: list[int] = []
    timer = node.create_timer(
        0.002, lambda: ticks.append(1), clock=Clock(clock_type=ClockType.STEADY_TIME)
    )
    assert spin_until(executor, lambda: len(ticks) >= 20)
    assert executor._quiet is not None  # (the one-timer way was taken)
    timer.cancel()
    stopped_at = len(ticks)
    for _ in range(5):
        executor.spin_once(timeout_sec=0.01)  # returns at its timeout with nothing to run
    assert len(ticks) == stopped_at
    timer.reset()
    assert spin_until(executor, lambda: len(ticks) >= stopped_at + 10)


def test_a_timer_that_outlasts_its_period_does_not_keep_messages_from_being_read(ros):
    # always due (its callback takes longer than its period), so no wait comes between its
    # calls: the timers-only look still polls, and its node's subscription gets every message
    from rosl.idl.registry import get_message_class

    node, executor = settled(ros, "overrun")
    String = get_message_class("std_msgs/msg/String")
    heard: list[str] = []
    node.create_subscription(String, "/overrun", lambda m: heard.append(m.data), 100)
    talker = ros.Node("overrun_talker").create_publisher(String, "/overrun", 100)
    ticks: list[int] = []

    def tick() -> None:
        ticks.append(1)
        time.sleep(0.003)

    timer = node.create_timer(0.05, tick)
    assert spin_until(executor, lambda: len(ticks) >= 3)
    assert executor._quiet is not None  # (the timers-only look is the one under test)
    timer.timer_period_ns = 1_000_000
    assert spin_until(executor, lambda: len(ticks) >= 10)
    for i in range(3):
        talker.publish(String(data=f"m{i}"))
    assert spin_until(executor, lambda: len(heard) == 3), heard
    assert heard == ["m0", "m1", "m2"]
    # and the usual look (a change was notified: a new node here) polls too, for messages
    # sent from another thread while the timer keeps overrunning
    ros.Node("overrun_bystander")

    def talk() -> None:
        for i in range(3, 13):
            talker.publish(String(data=f"m{i}"))
            time.sleep(0.02)

    threading.Thread(target=talk, daemon=True).start()
    assert spin_until(executor, lambda: len(heard) == 13), heard
    assert heard == [f"m{i}" for i in range(13)]


def test_an_executor_that_decides_can_execute_itself_is_asked_for_timers_too(ros):
    class Picky(SingleThreadedExecutor):
        refused: ClassVar[set[Any]] = set()

        def can_execute(self, entity: Any) -> bool:
            return entity not in self.refused and super().can_execute(entity)

    node = ros.Node("picky")
    startup = list(node.timers)
    executor = Picky()
    executor.add_node(node)
    settle(executor, node, startup)
    refused: list[int] = []
    allowed: list[int] = []
    first = node.create_timer(0.01, lambda: refused.append(1))
    node.create_timer(0.013, lambda: allowed.append(1))
    assert spin_until(executor, lambda: len(refused) >= 5)
    Picky.refused.add(first)
    before = len(refused)
    assert spin_until(executor, lambda: len(allowed) >= 30)
    assert len(refused) == before
