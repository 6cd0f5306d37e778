"""QoS events as rclpy names them: the status records and the callbacks a user gives.

``create_publisher(..., event_callbacks=PublisherEventCallbacks(...))`` and
``create_subscription(..., event_callbacks=SubscriptionEventCallbacks(...))`` take these; the
records carry rmw's field names (``total_count``, ``total_count_change``, ``alive_count``...).
What raises the events lives in :mod:`rosl.node.qos_watch`.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

from rosl.node.qos import QoSPolicyKind

if TYPE_CHECKING:
    from collections.abc import Callable


@dataclass(slots=True)
class QoSRequestedDeadlineMissedInfo:
    """A subscription went a deadline period without a message."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(slots=True)
class QoSOfferedDeadlineMissedInfo:
    """A publisher went a deadline period without publishing."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(slots=True)
class QoSLivelinessChangedInfo:
    """The publishers a subscription matches became alive or not alive."""

    alive_count: int = 0
    not_alive_count: int = 0
    alive_count_change: int = 0
    not_alive_count_change: int = 0


@dataclass(slots=True)
class QoSLivelinessLostInfo:
    """A manual-by-topic publisher let its lease run out."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(slots=True)
class QoSRequestedIncompatibleQoSInfo:
    """Endpoints found on the topic whose QoS does not match (the last policy that failed)."""

    total_count: int = 0
    total_count_change: int = 0
    last_policy_kind: QoSPolicyKind = QoSPolicyKind.INVALID


QoSOfferedIncompatibleQoSInfo = QoSRequestedIncompatibleQoSInfo


@dataclass(slots=True)
class QoSMessageLostInfo:
    """Messages a subscription never received (sequence gaps)."""

    total_count: int = 0
    total_count_change: int = 0


@dataclass(slots=True)
class QoSSubscriptionMatchedInfo:
    """The compatible publishers a subscription matches: all told, and now (Jazzy)."""

    total_count: int = 0
    total_count_change: int = 0
    current_count: int = 0
    current_count_change: int = 0


QoSPublisherMatchedInfo = QoSSubscriptionMatchedInfo


@dataclass(slots=True)
class IncompatibleTypeInfo:
    """Endpoints found on the topic with another message type (Jazzy)."""

    total_count: int = 0
    total_count_change: int = 0


class QoSPublisherEventType(enum.IntEnum):
    """rcl's publisher event types."""

    RCL_PUBLISHER_OFFERED_DEADLINE_MISSED = 0
    RCL_PUBLISHER_LIVELINESS_LOST = 1
    RCL_PUBLISHER_OFFERED_INCOMPATIBLE_QOS = 2
    RCL_PUBLISHER_INCOMPATIBLE_TYPE = 3
    RCL_PUBLISHER_MATCHED = 4


class QoSSubscriptionEventType(enum.IntEnum):
    """rcl's subscription event types."""

    RCL_SUBSCRIPTION_REQUESTED_DEADLINE_MISSED = 0
    RCL_SUBSCRIPTION_LIVELINESS_CHANGED = 1
    RCL_SUBSCRIPTION_REQUESTED_INCOMPATIBLE_QOS = 2
    RCL_SUBSCRIPTION_MESSAGE_LOST = 3
    RCL_SUBSCRIPTION_INCOMPATIBLE_TYPE = 4
    RCL_SUBSCRIPTION_MATCHED = 5


class UnsupportedEventTypeError(Exception):
    """An event type this middleware does not raise (rclpy's name; every one above is)."""


class SubscriptionEventCallbacks:
    """The event callbacks of a subscription (rclpy.event_handler / rclpy.qos_event)."""

    def __init__(
        self,
        *,
        deadline: Callable[[QoSRequestedDeadlineMissedInfo], None] | None = None,
        incompatible_qos: Callable[[QoSRequestedIncompatibleQoSInfo], None] | None = None,
        liveliness: Callable[[QoSLivelinessChangedInfo], None] | None = None,
        message_lost: Callable[[QoSMessageLostInfo], None] | None = None,
        incompatible_type: Callable[[IncompatibleTypeInfo], None] | None = None,
        matched: Callable[[QoSSubscriptionMatchedInfo], None] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        self.deadline = deadline
        self.incompatible_qos = incompatible_qos
        self.liveliness = liveliness
        self.message_lost = message_lost
        self.incompatible_type = incompatible_type
        self.matched = matched
        self.use_default_callbacks = use_default_callbacks


class PublisherEventCallbacks:
    """The event callbacks of a publisher (rclpy.event_handler / rclpy.qos_event)."""

    def __init__(
        self,
        *,
        deadline: Callable[[QoSOfferedDeadlineMissedInfo], None] | None = None,
        liveliness: Callable[[QoSLivelinessLostInfo], None] | None = None,
        incompatible_qos: Callable[[QoSOfferedIncompatibleQoSInfo], None] | None = None,
        incompatible_type: Callable[[IncompatibleTypeInfo], None] | None = None,
        matched: Callable[[QoSPublisherMatchedInfo], None] | None = None,
        use_default_callbacks: bool = True,
    ) -> None:
        self.deadline = deadline
        self.liveliness = liveliness
        self.incompatible_qos = incompatible_qos
        self.incompatible_type = incompatible_type
        self.matched = matched
        self.use_default_callbacks = use_default_callbacks
