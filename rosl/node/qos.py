"""Quality of service: rclpy's QoSProfile, policy enums and preset profiles.

Over multicast every message is sent once, best effort; what the words change here is the
history kept (``depth``) and durability: ``TRANSIENT_LOCAL`` publishers keep their last
``depth`` messages and replay them to late transient-local subscribers (as /tf_static and
/robot_description need). Reliability words are carried and shown (``topic info -v``), and
loss is counted per publisher instead of hidden.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, replace
from typing import Any


class HistoryPolicy(enum.IntEnum):
    """How many messages to keep."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3

    @property
    def short_key(self) -> str:
        """The lowercase word used on the command line."""
        return self.name.lower()


class ReliabilityPolicy(enum.IntEnum):
    """Whether lost messages are retried (multicast: never; loss is counted)."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4

    @property
    def short_key(self) -> str:
        """The lowercase word used on the command line."""
        return self.name.lower()


class DurabilityPolicy(enum.IntEnum):
    """Whether late subscribers get earlier messages."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4

    @property
    def short_key(self) -> str:
        """The lowercase word used on the command line."""
        return self.name.lower()


class LivelinessPolicy(enum.IntEnum):
    """How liveliness is asserted (always automatic here)."""

    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5

    @property
    def short_key(self) -> str:
        """The lowercase word used on the command line."""
        return self.name.lower()


# rclpy's older names
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy


@dataclass(slots=True)
class QoSProfile:
    """A QoS profile, as rclpy's: ``QoSProfile(depth=10)`` or with explicit policies."""

    history: HistoryPolicy = HistoryPolicy.KEEP_LAST
    depth: int = 10
    reliability: ReliabilityPolicy = ReliabilityPolicy.RELIABLE
    durability: DurabilityPolicy = DurabilityPolicy.VOLATILE
    liveliness: LivelinessPolicy = LivelinessPolicy.AUTOMATIC
    lifespan: Any = None
    deadline: Any = None
    liveliness_lease_duration: Any = None
    avoid_ros_namespace_conventions: bool = False

    def __init__(self, **kwargs: Any) -> None:
        if "history" not in kwargs and "depth" not in kwargs:
            raise ValueError("QoSProfile needs history and/or depth, e.g. QoSProfile(depth=10)")
        self.history = HistoryPolicy(kwargs.pop("history", HistoryPolicy.KEEP_LAST))
        self.depth = int(kwargs.pop("depth", 10 if self.history is HistoryPolicy.KEEP_LAST else 0))
        self.reliability = ReliabilityPolicy(kwargs.pop("reliability", ReliabilityPolicy.RELIABLE))
        self.durability = DurabilityPolicy(kwargs.pop("durability", DurabilityPolicy.VOLATILE))
        self.liveliness = LivelinessPolicy(kwargs.pop("liveliness", LivelinessPolicy.AUTOMATIC))
        self.lifespan = kwargs.pop("lifespan", None)
        self.deadline = kwargs.pop("deadline", None)
        self.liveliness_lease_duration = kwargs.pop("liveliness_lease_duration", None)
        self.avoid_ros_namespace_conventions = bool(
            kwargs.pop("avoid_ros_namespace_conventions", False)
        )
        if kwargs:
            raise TypeError(f"QoSProfile got unknown settings: {', '.join(sorted(kwargs))}")
        if self.depth < 0:
            raise ValueError("QoSProfile depth must be >= 0")

    def words(self) -> dict[str, Any]:
        """The profile as plain words, for discovery and ``topic info -v``."""
        return {
            "reliability": self.reliability.name,
            "durability": self.durability.name,
            "history": self.history.name,
            "depth": self.depth,
            "liveliness": self.liveliness.name,
        }

    @property
    def keeps_history(self) -> bool:
        """Whether messages are kept for late subscribers."""
        return self.durability is DurabilityPolicy.TRANSIENT_LOCAL


def _profile(**kwargs: Any) -> QoSProfile:
    return QoSProfile(**kwargs)


qos_profile_system_default = _profile(history=HistoryPolicy.SYSTEM_DEFAULT, depth=10)
qos_profile_default = _profile(depth=10)
qos_profile_sensor_data = _profile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
qos_profile_services_default = _profile(depth=10)
qos_profile_parameters = _profile(depth=1000)
qos_profile_parameter_events = _profile(depth=1000)
qos_profile_action_status_default = _profile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
qos_profile_rosout_default = _profile(depth=1000, durability=DurabilityPolicy.TRANSIENT_LOCAL)
qos_profile_unknown = _profile(history=HistoryPolicy.UNKNOWN, depth=0)


class QoSPresetProfiles(enum.Enum):
    """Named profiles, as rclpy's ``QoSPresetProfiles``."""

    UNKNOWN = qos_profile_unknown
    DEFAULT = qos_profile_default
    SYSTEM_DEFAULT = qos_profile_system_default
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = qos_profile_services_default
    PARAMETERS = qos_profile_parameters
    PARAMETER_EVENTS = qos_profile_parameter_events
    ACTION_STATUS_DEFAULT = qos_profile_action_status_default

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        """Return a copy of the profile called ``name`` (``sensor_data``, ``default``...)."""
        return replace(cls[name.upper()].value)


def as_profile(
    qos: QoSProfile | int | None, default: QoSProfile = qos_profile_default
) -> QoSProfile:
    """Accept a profile or a plain depth, as rclpy's create_* do."""
    if qos is None:
        return replace(default)
    if isinstance(qos, QoSProfile):
        return qos
    if isinstance(qos, int) and not isinstance(qos, bool):
        return QoSProfile(depth=qos)
    raise TypeError(f"expected a QoSProfile or a history depth, got {qos!r}")
