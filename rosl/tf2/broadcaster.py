"""tf2_ros's broadcasters: transforms onto /tf, and static ones onto /tf_static.

The static broadcaster keeps every child frame it was given and publishes them all each
time (as tf2_ros's C++ one does), so a listener that joins late gets every static frame
from the one transient-local message kept.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class
from rosl.node.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

if TYPE_CHECKING:
    from rosl.node.node import Node


def _as_list(transform: Any) -> list[Any]:
    if isinstance(transform, list):
        return transform
    if hasattr(transform, "__iter__"):
        return list(transform)
    return [transform]


class TransformBroadcaster:
    """Sends transforms on /tf (tf2_ros.TransformBroadcaster)."""

    def __init__(self, node: Node, qos: QoSProfile | int | None = None) -> None:
        self._message = get_message_class("tf2_msgs/msg/TFMessage")
        self.pub_tf = node.create_publisher(
            self._message, "/tf", QoSProfile(depth=100) if qos is None else qos
        )

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 - tf2_ros's name
        """Publish a TransformStamped or a list of them."""
        self.pub_tf.publish(self._message(transforms=_as_list(transform)))

    send_transform = sendTransform


class StaticTransformBroadcaster:
    """Sends static transforms on /tf_static, latched (tf2_ros.StaticTransformBroadcaster)."""

    def __init__(self, node: Node, qos: QoSProfile | int | None = None) -> None:
        if qos is None:
            qos = QoSProfile(
                depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )  # fmt: skip
        self._message = get_message_class("tf2_msgs/msg/TFMessage")
        self.pub_tf = node.create_publisher(self._message, "/tf_static", qos)
        self._by_child: dict[str, Any] = {}

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 - tf2_ros's name
        """Publish these static transforms along with every one sent before."""
        for one in _as_list(transform):
            self._by_child[one.child_frame_id] = one
        self.pub_tf.publish(self._message(transforms=list(self._by_child.values())))

    send_transform = sendTransform


__all__ = ["StaticTransformBroadcaster", "TransformBroadcaster"]
