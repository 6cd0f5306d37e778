"""launch_testing_ros's ``WaitForTopics``: wait until given topics carry messages, in a test.

As ROS 2's: ``WaitForTopics([("chatter", String)], timeout=5.0)`` subscribes from a node of its
own and ``wait()`` says whether every topic had a message within ``timeout``; as a context
manager it raises RuntimeError naming the silent topics, and ends its node on leaving.
``topics_received``, ``topics_not_received`` and ``received_messages`` tell what came (the
last ``messages_received_buffer_length`` messages of each topic).
"""

from __future__ import annotations

import itertools
import time
from collections import deque
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from types import TracebackType

_NAMES = itertools.count(1)


class WaitForTopics:
    """Wait for messages on a list of ``(topic name, message type)``."""

    def __init__(
        self,
        topic_tuples: list[tuple[str, Any]],
        timeout: float = 5.0,
        messages_received_buffer_length: int = 10,
    ) -> None:
        self.topic_tuples = list(topic_tuples)
        self.timeout = timeout
        self._received = {
            name: deque[Any](maxlen=max(1, messages_received_buffer_length))
            for name, _ in self.topic_tuples
        }
        self._node: Any = None
        self._started_context = False

    def wait(self) -> bool:
        """Whether every topic had a message within ``timeout`` (spins a node of its own)."""
        import rosl

        if self._node is None:
            if not rosl.ok():
                rosl.init([])
                self._started_context = True
            self._node = rosl.create_node(f"_wait_for_topics_{next(_NAMES)}")
            for name, message_type in self.topic_tuples:
                self._node.create_subscription(message_type, name, self._keeper(name), 10)
        deadline = time.monotonic() + self.timeout
        while self.topics_not_received() and time.monotonic() < deadline:
            rosl.spin_once(self._node, timeout_sec=min(0.1, max(0.0, deadline - time.monotonic())))
        return not self.topics_not_received()

    def _keeper(self, name: str) -> Any:
        def keep(message: Any) -> None:
            self._received[name].append(message)

        return keep

    def shutdown(self) -> None:
        """End the node (and rosl's context, when this object started it)."""
        import rosl

        if self._node is not None:
            self._node.destroy_node()
            self._node = None
        if self._started_context:
            self._started_context = False
            rosl.try_shutdown()

    def topics_received(self) -> set[str]:
        """The topics (as named) that had a message."""
        return {name for name, messages in self._received.items() if messages}

    def topics_not_received(self) -> set[str]:
        """The topics (as named) that had none."""
        return {name for name, messages in self._received.items() if not messages}

    def received_messages(self, topic_name: str) -> list[Any]:
        """The messages kept for a topic (as named), oldest first.

        Raises:
            KeyError: a topic it was not asked to wait for.
        """
        if topic_name not in self._received:
            raise KeyError(f"WaitForTopics was not asked to wait for '{topic_name}'")
        return list(self._received[topic_name])

    def __enter__(self) -> WaitForTopics:
        """Wait; raise RuntimeError naming the topics that had no message."""
        if not self.wait():
            silent = sorted(self.topics_not_received())
            self.shutdown()
            raise RuntimeError(f"Did not receive messages on these topics: {silent}")
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        """End the node."""
        self.shutdown()
