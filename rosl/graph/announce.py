"""The per-process discovery thread: hello, goodbye, graph queries, and the loopback self-test.

Wire format: JSON objects in ``Kind.DISCOVERY`` datagrams on channel 0, each with an ``op``:

* ``hello``: a process's nodes and endpoints (``records.to_json``), the processes it knows of
  (``known``) and, when answering a query, the query it answers (``reply_to``);
* ``bye``: the process is shutting down;
* ``query``: everyone answers at once with a ``hello``;
* anything else (e.g. ``replay`` for transient-local history) goes to a registered handler.

A query is complete when every process that anyone reported as known has answered it — so a
CLI waits exactly as long as the graph needs, with a bound for processes that died.
"""

from __future__ import annotations

import itertools
import json
import os
import platform
import sys
import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.bus.errors import BusError
from rosl.bus.header import Kind
from rosl.bus.wire import Delivery, Writer
from rosl.graph.cache import GraphCache
from rosl.graph.records import ProcessRecord, from_json, to_json

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.transport import Transport
    from rosl.graph.records import NodeRecord

DISCOVERY_TOPIC = "@discovery"
DISCOVERY_TYPE = "rosl/discovery/1"
PERIOD_S = 1.0
SELFTEST_S = 2.0
REASSEMBLY_BUDGET = 8 * 1024 * 1024  # announcements are small: strangers' fragments get little
HOST = platform.node()


@dataclass(slots=True)
class _Query:
    started: float
    echoed: float = 0.0
    responders: set[int] = field(default_factory=set)
    known: set[int] = field(default_factory=set)
    last_answer: float = 0.0


class Discovery:
    """Announces this process's nodes and keeps the :class:`GraphCache` of everyone else's."""

    def __init__(
        self,
        transport: Transport,
        sender: int,
        describe: Callable[[], list[NodeRecord]],
    ) -> None:
        self.sender = sender
        self.cache = GraphCache()
        self.handlers: dict[str, Callable[[dict[str, Any]], None]] = {}
        self.loopback_ok = threading.Event()
        self.malformed = 0
        self.lockstep = False  # announced: this process answers lock-stepped simulators
        # told the sender id of every process that said goodbye or whose lease ran out
        self.on_gone: list[Callable[[int], None]] = []
        self._describe = describe
        self._transport = transport
        self._writer = Writer(
            transport, sender, 0, DISCOVERY_TOPIC, DISCOVERY_TYPE, Kind.DISCOVERY, channel=0
        )
        self._receiver = transport.receiver()
        self._reader = self._receiver.reader
        self._reader.wanted.add(self._writer.topic)
        self._reader.reassembler.budget = REASSEMBLY_BUDGET
        self._receiver.join(0)
        self._version = itertools.count(1)
        self._announced = ""  # what the current version of our record says (its JSON)
        self._current = 0  # the version of our record: it changes only with its content
        self._query_ids = itertools.count(1)
        self._queries: dict[int, _Query] = {}
        self._lock = threading.Lock()
        self._announce_due = 0.0
        self._pending_replies: list[str] = []  # "querier:qid" we still owe an answer
        self._later: list[tuple[float, dict[str, Any]]] = []  # (when, op) to send again
        self._stopping = False
        self._has_announced = False
        self.started = time.monotonic()  # when discovery began listening
        self._warned = False
        self._thread = threading.Thread(target=self._run, name="rosl-discovery", daemon=True)
        self.first_query = 0  # the query sent at start (see start())

    # --- lifecycle ---------------------------------------------------------------------------

    def start(self) -> None:
        """Start the thread; the first announcement and a graph query go out at once.

        A caller that wants the graph soon waits for :attr:`first_query` rather than asking
        again: everyone has been answering it since this process started.
        """
        self._thread.start()
        self.changed()
        self.first_query = self.query()

    def stop(self) -> None:
        """Say goodbye and stop the thread (idempotent)."""
        if self._stopping:
            return
        self._stopping = True
        self._wake()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(timeout=2.0)
        # last, so no announcement still being made can overtake the goodbye
        self._send({"op": "bye", "sender": f"{self.sender:016x}"})
        self._receiver.close()

    def changed(self) -> None:
        """Local nodes changed: announce them now."""
        self._announce_due = 0.0
        self._wake()

    def _wake(self) -> None:
        self._receiver.wake()

    # --- queries -----------------------------------------------------------------------------

    def query(self) -> int:
        """Ask every process to announce itself now; return the query's id."""
        qid = next(self._query_ids)
        with self._lock:
            self._queries[qid] = _Query(time.monotonic())
        self._send({"op": "query", "qid": qid, "sender": f"{self.sender:016x}"})
        return qid

    def wait_complete(self, qid: int, timeout: float = 1.0, quiet: float = 0.15) -> bool:
        """Wait until query ``qid`` is answered by every process anyone knows of.

        Args:
            qid: from :meth:`query`.
            timeout: the bound on the whole wait (seconds).
            quiet: when nobody at all answers, how long after our own query came back (and
                after this call) to conclude the graph is empty.

        Returns:
            True when complete, False when the bound was hit (some process did not answer).

        Raises:
            BusError: our own query never came back: multicast does not work here.
        """
        called = time.monotonic()  # quiet counts from here too (the query may be older)
        deadline = called + timeout
        echo_deadline = called + max(timeout, 1.0)
        while True:
            with self._lock:
                state = self._queries[qid]
                echoed, answered = state.echoed, set(state.responders)
                known = state.known | answered
            now = time.monotonic()
            if echoed:
                if answered and known <= answered:
                    return True
                if not answered and now - max(echoed, called) >= quiet:
                    return True
                if now >= deadline:
                    return False
            elif now >= echo_deadline:
                raise BusError(self.selftest_message())
            time.sleep(0.002)

    def selftest_message(self) -> str:
        """The one-line explanation when our own datagrams do not come back."""
        transport = self._transport
        return (
            f"{transport.name} does not work here: this process never received its own "
            f"datagram on {transport.describe()}; {transport.fix_hint}"
        )

    def dropped(self) -> dict[str, int]:
        """What the discovery channel refused so far, by reason (see ``Reader.dropped``)."""
        return self._reader.dropped()

    def send(self, message: dict[str, Any], again_after: float | None = None) -> None:
        """Send another op (e.g. ``replay``) to every process.

        With ``again_after``, the discovery thread sends it once more that many seconds later:
        for a one-off request whose loss nothing else would repair (a late subscriber's ask
        for history); receivers must take it twice as once.
        """
        self._send(message)
        if again_after is not None:
            with self._lock:
                self._later.append((time.monotonic() + again_after, message))

    # --- the thread --------------------------------------------------------------------------

    def _send(self, message: dict[str, Any]) -> None:
        data = json.dumps(message, separators=(",", ":")).encode()
        try:
            self._writer.send(data)
        except BusError:
            if not self._stopping:
                raise

    def _announce(self, reply_to: list[str]) -> None:
        nodes = tuple(self._describe())
        if not nodes:
            if self._has_announced:  # the last node went away: leave the graph now
                self._has_announced = False
                self._send({"op": "bye", "sender": f"{self.sender:016x}"})
            return
        self._has_announced = True
        shm = getattr(self._transport, "shm", None)
        record = ProcessRecord(
            self.sender, os.getpid(), HOST, nodes, 0, lockstep=self.lockstep,
            shm="" if shm is None else shm.host,
        )  # fmt: skip
        process = to_json(record)
        content = json.dumps(process, separators=(",", ":"))  # (stats are live: compare text)
        if content != self._announced:  # receivers decode a record only when its version is new
            self._announced, self._current = content, next(self._version)
        process["version"] = self._current
        known = [f"{s:016x}" for s in self.cache.senders()]
        self._send({"op": "hello", "process": process, "known": known, "reply_to": reply_to})

    def _run(self) -> None:
        deliveries: list[Delivery] = []
        while not self._stopping:
            now = time.monotonic()
            if self._announce_due <= now or self._pending_replies:
                replies, self._pending_replies = self._pending_replies, []
                self._announce_due = now + PERIOD_S
                try:
                    self._announce(replies)
                except Exception as err:
                    print(f"rosl: discovery: cannot announce: {err}", file=sys.stderr)
            for process in self.cache.expire(now):
                self._gone(process.sender)
            if self._later:
                self._send_due(now)
            self._check_selftest(now)
            wait = max(0.0, min(self._announce_due - time.monotonic(), 0.5))
            deliveries.clear()
            self._receiver.poll(wait, deliveries)
            for delivery in deliveries:
                self._handle(delivery)

    def _send_due(self, now: float) -> None:
        with self._lock:
            due = [message for when, message in self._later if when <= now]
            self._later = [(when, message) for when, message in self._later if when > now]
        for message in due:
            try:
                self._send(message)
            except Exception as err:  # (as an announcement's: the thread goes on)
                print(f"rosl: discovery: cannot send: {err}", file=sys.stderr)

    def _check_selftest(self, now: float) -> None:
        if self.loopback_ok.is_set() or self._warned or now - self.started < SELFTEST_S:
            return
        self._warned = True
        print(f"rosl: error: {self.selftest_message()}", file=sys.stderr)

    def _handle(self, delivery: Delivery) -> None:
        try:
            message = json.loads(bytes(delivery.payload))
            op = message["op"]
        except (ValueError, KeyError, TypeError, RecursionError):
            self.malformed += 1
            return
        if delivery.sender == self.sender:
            self.loopback_ok.set()
        try:
            if op == "hello":
                self._on_hello(message, delivery.sender)
            elif op == "bye":
                if int(message["sender"], 16) != delivery.sender:
                    self.malformed += 1  # a process says goodbye for itself only
                    return
                self.cache.remove(delivery.sender)
                self._gone(delivery.sender)
            elif op == "query":
                self._on_query(message, delivery.sender)
            elif op in self.handlers:
                self.handlers[op](message)
        except (ValueError, KeyError, TypeError, AttributeError, OverflowError, RecursionError):
            self.malformed += 1  # one bad datagram must never stop discovery

    def _gone(self, sender: int) -> None:
        self._reader.forget(sender)
        for callback in self.on_gone:
            callback(sender)

    def _on_hello(self, message: dict[str, Any], sender: int) -> None:
        process = message["process"]
        now = time.monotonic()
        # a process repeats its record every period: the version it had renews the lease, with
        # no decoding (with many processes, decoding every record each second adds up)
        if not self.cache.renew(sender, int(process["version"]), now):
            record = from_json(process, now)
            if record.sender != sender:
                self.malformed += 1
                return
            self.cache.update(record)
        known = {int(s, 16) for s in message.get("known", [])}
        mine = f"{self.sender:016x}:"
        with self._lock:
            for answered in message.get("reply_to") or []:
                if not str(answered).startswith(mine):
                    continue
                state = self._queries.get(int(str(answered)[len(mine) :]))
                if state is not None:
                    state.responders.add(sender)
                    state.known |= known
                    state.last_answer = time.monotonic()

    def _on_query(self, message: dict[str, Any], sender: int) -> None:
        qid = int(message["qid"])
        if sender == self.sender:
            with self._lock:
                state = self._queries.get(qid)
                if state is not None and not state.echoed:
                    state.echoed = time.monotonic()
        self._pending_replies.append(f"{sender:016x}:{qid}")
