"""init / ok / shutdown: the process's ROS arguments, participant, and Ctrl-C handling.

The first SIGINT or SIGTERM asks for a clean shutdown (``ok()`` turns false, ``spin`` returns)
so a node's own cleanup runs; a second SIGINT raises KeyboardInterrupt as usual. Goodbyes go
out at ``shutdown()`` or, if the program never calls it, at exit.
"""

from __future__ import annotations

import atexit
import signal
import sys
import threading
from typing import TYPE_CHECKING, Any

from rosl.node import logging as rlog
from rosl.node import ros_args
from rosl.node.errors import NotInitializedError

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.node import Node
    from rosl.node.participant import Participant


class Context:
    """One init/shutdown cycle of rosl in this process (rclpy.context.Context)."""

    def __init__(self) -> None:
        self.args = ros_args.RosArgs()
        self.domain_id: int | str | None = None
        self.participant: Participant | None = None
        self.nodes: list[Node] = []
        self.callback_errors = "log"  # or "raise"
        self._initialized = False
        self._shutdown_requested = False
        self.signalled: int | None = None  # the SIGINT/SIGTERM that asked for the shutdown
        self._on_shutdown: list[Callable[[], None]] = []
        self._previous: dict[int, Any] = {}
        self._lock = threading.RLock()

    def init(self, args: list[str] | None = None, *, domain_id: int | str | None = None) -> None:
        """Read ROS arguments (``sys.argv`` by default) and get ready to create nodes."""
        with self._lock:
            self.args = ros_args.parse(sys.argv if args is None else list(args))
            self.domain_id = domain_id
            self._initialized = True
            self._shutdown_requested = False
            rlog.set_console_output(self.args.enable_stdout_logs)
            for name, level in self.args.log_levels.items():
                if name is None:
                    rlog.set_default_level(level)
                else:
                    rlog.set_logger_level(name, level)
            self._install_signal_handlers()
            atexit.register(self.try_shutdown)

    def ok(self) -> bool:
        """Whether the context is initialized and not shut down (or asked to)."""
        return self._initialized and not self._shutdown_requested

    def ensure_participant(self) -> Participant:
        """The process's participant, created on first use."""
        if not self._initialized:
            raise NotInitializedError("call rosl.init() (rclpy.init()) before creating nodes")
        with self._lock:
            if self.participant is None or self.participant.closed:
                from rosl.node.participant import Participant

                self.participant = Participant(self.domain_id)
            return self.participant

    def on_shutdown(self, callback: Callable[[], None]) -> None:
        """Run ``callback`` at shutdown."""
        self._on_shutdown.append(callback)

    def request_shutdown(self) -> None:
        """Make ``ok()`` false and wake spinning threads (safe in a signal handler)."""
        self._shutdown_requested = True
        self.wake_executors()

    def wake_executors(self) -> None:
        """Make executors waiting for work look again (something they wait for changed)."""
        participant = self.participant
        if participant is not None:
            participant.notify()

    def shutdown(self) -> None:
        """Destroy every node, say goodbye on the bus, and close sockets."""
        with self._lock:
            if not self._initialized:
                raise NotInitializedError("rosl.shutdown() called before rosl.init()")
            self._shutdown_requested = True
            for callback in list(self._on_shutdown):
                callback()
            self._on_shutdown.clear()
            for node in list(self.nodes):
                node.destroy_node()
            if self.participant is not None:
                self.participant.close()
                self.participant = None
            self._initialized = False
            self._restore_signal_handlers()

    def try_shutdown(self) -> None:
        """Shut down if initialized (idempotent)."""
        if self._initialized:
            self.shutdown()

    # --- signals -----------------------------------------------------------------------------

    def _install_signal_handlers(self) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        for sig in (signal.SIGINT, signal.SIGTERM):
            current = signal.getsignal(sig)
            if current is self._handle_signal:
                continue
            self._previous[sig] = current
            signal.signal(sig, self._handle_signal)

    def _restore_signal_handlers(self) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        for sig, previous in self._previous.items():
            if signal.getsignal(sig) is self._handle_signal:
                signal.signal(sig, previous if previous is not None else signal.SIG_DFL)
        self._previous.clear()

    def _handle_signal(self, signum: int, frame: Any) -> None:
        if self._shutdown_requested:
            if signum == signal.SIGINT:
                raise KeyboardInterrupt
            raise SystemExit(128 + signum)
        self.signalled = signum
        self.request_shutdown()


default_context = Context()
