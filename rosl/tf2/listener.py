"""tf2_ros's ``TransformListener``: /tf and /tf_static into a :class:`~rosl.tf2.buffer.Buffer`.

Subscribes with tf2_ros's QoS (/tf: depth 100; /tf_static: depth 100, transient local, so
a late listener still gets every static transform) in a reentrant callback group. The
buffer may drain these subscriptions itself while a blocking lookup waits.
"""

from __future__ import annotations

import contextlib
import threading
from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class
from rosl.node.callback_groups import ReentrantCallbackGroup
from rosl.node.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

if TYPE_CHECKING:
    from rosl.node.node import Node
    from rosl.node.participant import Participant
    from rosl.node.subscription import Subscription
    from rosl.tf2.buffer import Buffer

DEFAULT_TF_TOPIC = "/tf"
DEFAULT_STATIC_TF_TOPIC = "/tf_static"
AUTHORITY = "default_authority"


class TransformListener:
    """Feeds a buffer from /tf and /tf_static (tf2_ros.TransformListener)."""

    def __init__(
        self,
        buffer: Buffer,
        node: Node | None = None,
        *,
        spin_thread: bool = False,
        qos: QoSProfile | int | None = None,
        static_qos: QoSProfile | int | None = None,
        tf_topic: str = DEFAULT_TF_TOPIC,
        tf_static_topic: str = DEFAULT_STATIC_TF_TOPIC,
        static_only: bool = False,
    ) -> None:
        self._buffer = buffer
        if node is None:
            node = _own_node(self)
        self.node = node
        self.participant: Participant | None = node.participant
        self.group = ReentrantCallbackGroup()
        tf_message: Any = get_message_class("tf2_msgs/msg/TFMessage")
        self._subscriptions: list[Subscription] = []
        if not static_only:
            self.tf_sub = node.create_subscription(
                tf_message, tf_topic, self.callback,
                QoSProfile(depth=100) if qos is None else qos, callback_group=self.group,
            )  # fmt: skip
            self._subscriptions.append(self.tf_sub)
        if static_qos is None:
            static_qos = QoSProfile(
                depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )  # fmt: skip
        self.tf_static_sub = node.create_subscription(
            tf_message, tf_static_topic, self.static_callback, static_qos,
            callback_group=self.group,
        )  # fmt: skip
        self._subscriptions.append(self.tf_static_sub)
        self._lock = threading.Lock()
        buffer.attach(self)
        if spin_thread:
            self._start_thread()

    @property
    def buffer(self) -> Buffer:
        """The buffer fed (may be replaced: the new one is fed, and drained while it waits)."""
        return self._buffer

    @buffer.setter
    def buffer(self, buffer: Buffer) -> None:
        self._buffer.detach(self)
        self._buffer = buffer
        buffer.attach(self)

    def _start_thread(self) -> None:
        from rosl.executor import SingleThreadedExecutor

        self.executor = SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.dedicated_listener_thread = threading.Thread(
            target=self._spin, name="tf_listener", daemon=True
        )
        self.dedicated_listener_thread.start()

    def _spin(self) -> None:
        from rosl.executor import ExternalShutdownException, ShutdownException

        with contextlib.suppress(ExternalShutdownException, ShutdownException):
            self.executor.spin()

    def callback(self, data: Any) -> None:
        """Store the dynamic transforms of one TFMessage."""
        for transform in data.transforms:
            self.buffer.set_transform(transform, AUTHORITY)

    def static_callback(self, data: Any) -> None:
        """Store the static transforms of one TFMessage."""
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, AUTHORITY)

    def drain(self) -> None:
        """Store what the subscriptions hold now (a blocking lookup waiting calls this)."""
        for subscription in self._subscriptions:
            subscription.drain()

    def stopped(self) -> bool:
        """Whether the node's context was shut down (Ctrl-C): blocking waits end then."""
        return not self.node.context.ok()

    def unregister(self) -> None:
        """Stop listening (and feeding the buffer)."""
        self.buffer.detach(self)
        for subscription in self._subscriptions:
            if not subscription.destroyed:
                self.node.destroy_subscription(subscription)
        self._subscriptions.clear()
        self.participant = None

    def __del__(self) -> None:
        executor = getattr(self, "executor", None)
        if executor is not None:
            executor.shutdown()


def _own_node(listener: TransformListener) -> Node:
    """The node tf2_ros makes when none is given: no rosout, no parameter services."""
    from rosl.node.node import Node
    from rosl.node.parameters import Parameter

    return Node(
        f"transform_listener_impl_{id(listener):010x}",
        enable_rosout=False,
        start_parameter_services=False,
        parameter_overrides=[Parameter("use_sim_time", value=False)],
    )


class StaticTransformListener(TransformListener):
    """Listens to /tf_static only (tf2_ros.StaticTransformListener)."""

    def __init__(self, buffer: Buffer, node: Node | None = None, **options: Any) -> None:
        super().__init__(buffer, node, static_only=True, **options)


__all__ = [
    "DEFAULT_STATIC_TF_TOPIC",
    "DEFAULT_TF_TOPIC",
    "StaticTransformListener",
    "TransformListener",
]
