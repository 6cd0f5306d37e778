"""Where a recorder's schemas come from, kept off the thread that receives messages.

A type is read from this process's .msg/.srv files or, when this process cannot read it,
asked of the publisher's process (``typedef_request`` on discovery; the answer comes on the
discovery thread). After ``PENDING_LIMIT_S`` without an answer its messages are recorded
without a schema. Once :meth:`Schemas.preload` has started, types are read on a thread of
their own as soon as the graph shows a publisher (or server) of them: the receiving thread,
which time-stamps messages, never waits for a parse; its messages are held meanwhile. Every
schema that arrives off the receiving thread sets :attr:`Schemas.arrived` and wakes it.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.participant import Participant

PENDING_LIMIT_S = 3.0
REQUEST_POLL_S = 0.05

Schema = tuple[str, str, str]  # encoding, text, RIHS01 type hash


class Schemas:
    """The schemas of the types a recorder meets, by type name."""

    def __init__(self, participant: Participant, log: Callable[[str], None]) -> None:
        self._participant = participant
        self._log = log
        self._known: dict[str, Schema] = {}
        self._unreadable: set[str] = set()  # not in this process's files: asked of others
        self._asked: dict[str, float] = {}
        self._requested: set[str] = set()  # loads the receiving thread waits for
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._stopping = False
        self.arrived = False  # a schema came off the receiving thread (cleared by the reader)
        participant.discovery.handlers["typedef"] = self._on_typedef

    def get(self, type_name: str) -> Schema | None:
        """The schema of a type; None while it is being read or asked for."""
        with self._lock:
            found = self._known.get(type_name)
            if found is not None:
                return found
            unreadable = type_name in self._unreadable
            background = self._thread is not None and not unreadable
            if background:
                self._requested.add(type_name)
        if background:
            return None
        if not unreadable:
            found = self._load(type_name)
            if found is not None:
                return found
        return self._ask(type_name)

    # --- the preloading thread ---------------------------------------------------------------

    def preload(self, wanted: Callable[[], set[str]]) -> None:
        """Read types on a thread of their own from now on (idempotent).

        At each graph change the thread reads the types ``wanted()`` names; it also reads those
        :meth:`get` was asked for.
        """
        if self._thread is not None or self._stopping:
            return
        self._thread = threading.Thread(
            target=self._run, args=(wanted,), name="rosl-recorder-schemas", daemon=True
        )
        self._thread.start()

    def stop(self) -> None:
        """Stop the preloading thread; :meth:`get` reads types itself again."""
        self._stopping = True
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)

    def _run(self, wanted: Callable[[], set[str]]) -> None:
        graph = self._participant.graph
        generation = -1
        while not self._stopping:
            current = graph.wait_change(generation, REQUEST_POLL_S)
            with self._lock:
                todo, self._requested = self._requested, set()
            if current != generation:
                generation = current
                try:
                    todo |= wanted()
                except Exception as err:  # never let the thread die: log and go on
                    self._log(f"[WARN] [rosl_recorder]: cannot list the graph's types: {err}")
            fresh = False
            for type_name in sorted(todo):
                with self._lock:
                    done = type_name in self._known or type_name in self._unreadable
                if not done:
                    self._load(type_name)
                    fresh = True
            if fresh:
                self.arrived = True
                self._participant.notify()

    # --- reading and asking ------------------------------------------------------------------

    def _load(self, type_name: str) -> Schema | None:
        """Read a type from this process's files (None, and marked unreadable, when it cannot)."""
        from rosl.idl import registry
        from rosl.idl.errors import InterfaceError

        try:
            encoding, text = registry.schema(type_name)
            registry.get_message_class(type_name)  # built here, not when its messages come
            found = (encoding, text, registry.store().type_hash(type_name))
        except InterfaceError:
            found = None
        except Exception as err:  # a bug reading one type must not stop the recording
            self._log(f"[WARN] [rosl_recorder]: cannot read type {type_name}: {err}")
            found = None
        with self._lock:
            if found is None:
                self._unreadable.add(type_name)
            else:
                found = self._known.setdefault(type_name, found)
        return found

    def _ask(self, type_name: str) -> Schema | None:
        """Ask the publisher's process for a type this process cannot read."""
        now = time.monotonic()
        asked = self._asked.setdefault(type_name, now)
        if now - asked > PENDING_LIMIT_S:
            self._log(f"[WARN] [rosl_recorder]: nobody described type {type_name}; recording "
                      "its messages without a schema")  # fmt: skip
            with self._lock:
                return self._known.setdefault(type_name, ("", "", ""))
        if asked == now:
            self._participant.discovery.send({"op": "typedef_request", "type": type_name})
        return None

    def _on_typedef(self, message: dict[str, Any]) -> None:  # discovery thread
        with self._lock:
            self._known.setdefault(
                str(message["type"]),
                (str(message["encoding"]), str(message["text"]), str(message.get("hash", ""))),
            )
        self.arrived = True
        self._participant.notify()
