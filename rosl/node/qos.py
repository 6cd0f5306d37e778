"""Quality of service: rclpy's QoSProfile, policy enums, policy kinds and preset profiles.

Over multicast every message is sent once; what the words change here is the history kept
(``depth``), durability (``TRANSIENT_LOCAL`` publishers replay their last ``depth`` messages
to late transient-local subscribers), lifespan (older messages are not delivered), deadline and
liveliness (events, see :mod:`rosl.node.qos_watch`), and whether a publisher and a subscription
match at all (:mod:`rosl.node.qos_compatibility`). Loss is counted per publisher, not hidden.
"""

from __future__ import annotations

import enum
import warnings
from dataclasses import dataclass, replace
from typing import Any

from rosl.node.clock import Duration

INFINITE_NS = 2**63 - 1  # rmw's "infinite" duration
_INFINITE_SECONDS = 9223372036  # rmw's infinite as whole seconds (854775807 ns dropped)


class InvalidQoSProfileException(ValueError):  # noqa: N818 - rclpy's name
    """A QoSProfile built from settings that do not make one (rclpy's exception)."""

    def __init__(self, *args: object) -> None:
        super().__init__("Invalid QoSProfile", *args)


class _PolicyEnum(enum.IntEnum):
    """Base of the policy enums: the short (lowercase) keys the command line uses."""

    @classmethod
    def short_keys(cls) -> list[str]:
        """Every member's lowercase name."""
        return [name.lower() for name in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> int:
        """The value of the member called ``name`` (any case)."""
        return int(cls[name.upper()].value)

    @property
    def short_key(self) -> str:
        """The lowercase word used on the command line."""
        return self.name.lower()


def _deprecated_aliases(prefix: str) -> Any:
    """Give a policy enum rclpy's old ``RMW_QOS_POLICY_<KIND>_<NAME>`` names (with a warning)."""

    def decorate(cls: Any) -> Any:
        for member in list(cls.__members__):
            alias = f"RMW_QOS_POLICY_{prefix}_{member}"
            setattr(cls, alias, _DeprecatedAlias(member, alias))
        return cls

    return decorate


class _DeprecatedAlias:
    def __init__(self, name: str, attribute: str) -> None:
        self.name = name
        self.attribute = attribute

    def __get__(self, obj: object, cls: Any) -> Any:
        warnings.warn(
            f"{cls.__name__}.{self.attribute} is deprecated. Use {cls.__name__}.{self.name} "
            "instead.",
            DeprecationWarning,
            stacklevel=2,
        )
        return cls[self.name]


@_deprecated_aliases("HISTORY")
class HistoryPolicy(_PolicyEnum):
    """How many messages to keep."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3


@_deprecated_aliases("RELIABILITY")
class ReliabilityPolicy(_PolicyEnum):
    """What a subscription requires and a publisher offers; multicast retries nothing."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


@_deprecated_aliases("DURABILITY")
class DurabilityPolicy(_PolicyEnum):
    """Whether late subscribers get earlier messages."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


@_deprecated_aliases("LIVELINESS")
class LivelinessPolicy(_PolicyEnum):
    """How a publisher shows it is alive: its process's announcements, or its own calls."""

    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_NODE = 2  # deprecated in ROS 2; here as manual-by-topic, asserted by the node
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5


class QoSPolicyKind(enum.IntEnum):
    """The policies, as incompatible-QoS events and QoS overrides name them (rmw's numbers)."""

    INVALID = 1 << 0
    DURABILITY = 1 << 1
    DEADLINE = 1 << 2
    LIVELINESS = 1 << 3
    RELIABILITY = 1 << 4
    HISTORY = 1 << 5
    LIFESPAN = 1 << 6
    DEPTH = 1 << 7
    LIVELINESS_LEASE_DURATION = 1 << 8
    AVOID_ROS_NAMESPACE_CONVENTIONS = 1 << 9


MANUAL = (LivelinessPolicy.MANUAL_BY_NODE, LivelinessPolicy.MANUAL_BY_TOPIC)


def qos_policy_name_from_kind(policy_kind: QoSPolicyKind | int) -> str:
    """The policy's name (``RELIABILITY``...) from its kind."""
    return QoSPolicyKind(policy_kind).name


# rclpy's older names
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy


def duration_ns(value: Duration | None) -> int:
    """A policy duration in nanoseconds, 0 meaning none set (infinite)."""
    if value is None:
        return 0
    ns = value.nanoseconds
    if ns <= 0 or ns >= INFINITE_NS or ns // 1_000_000_000 >= _INFINITE_SECONDS:
        return 0
    return ns


def _duration(name: str, value: Any) -> Duration:
    if value is None:
        return Duration()
    if not isinstance(value, Duration):
        raise InvalidQoSProfileException(f"{name} must be a Duration, got {value!r}")
    return value


@dataclass(slots=True, init=False)
class QoSProfile:
    """A QoS profile, as rclpy's: ``QoSProfile(depth=10)`` or with explicit policies."""

    history: HistoryPolicy
    depth: int
    reliability: ReliabilityPolicy
    durability: DurabilityPolicy
    lifespan: Duration
    deadline: Duration
    liveliness: LivelinessPolicy
    liveliness_lease_duration: Duration
    avoid_ros_namespace_conventions: bool

    def __init__(self, **kwargs: Any) -> None:
        if "history" not in kwargs and "depth" not in kwargs:
            raise InvalidQoSProfileException(
                "QoSProfile needs history and/or depth, e.g. QoSProfile(depth=10)"
            )
        self.history = HistoryPolicy(kwargs.pop("history", HistoryPolicy.KEEP_LAST))
        self.depth = int(kwargs.pop("depth", 10 if self.history is HistoryPolicy.KEEP_LAST else 0))
        self.reliability = ReliabilityPolicy(kwargs.pop("reliability", ReliabilityPolicy.RELIABLE))
        self.durability = DurabilityPolicy(kwargs.pop("durability", DurabilityPolicy.VOLATILE))
        self.liveliness = LivelinessPolicy(kwargs.pop("liveliness", LivelinessPolicy.AUTOMATIC))
        self.lifespan = _duration("lifespan", kwargs.pop("lifespan", None))
        self.deadline = _duration("deadline", kwargs.pop("deadline", None))
        self.liveliness_lease_duration = _duration(
            "liveliness_lease_duration", kwargs.pop("liveliness_lease_duration", None)
        )
        self.avoid_ros_namespace_conventions = bool(
            kwargs.pop("avoid_ros_namespace_conventions", False)
        )
        if kwargs:
            raise TypeError(f"QoSProfile got unknown settings: {', '.join(sorted(kwargs))}")
        if self.depth < 0:
            raise InvalidQoSProfileException("QoSProfile depth must be >= 0")

    def words(self, subscription: bool = False) -> dict[str, Any]:
        """The profile as plain words, for discovery and ``topic info -v`` (durations in ns).

        ``SYSTEM_DEFAULT`` policies become what a DDS middleware uses: a reliable publisher, a
        best-effort subscription (``subscription=True``), volatile, keep-last, automatic.
        """
        reliable = ReliabilityPolicy.BEST_EFFORT if subscription else ReliabilityPolicy.RELIABLE
        return {
            "reliability": _in_force(self.reliability, reliable).name,
            "durability": _in_force(self.durability, DurabilityPolicy.VOLATILE).name,
            "history": _in_force(self.history, HistoryPolicy.KEEP_LAST).name,
            "depth": self.depth if self.history.name not in _VAGUE else max(1, self.depth),
            "liveliness": _in_force(self.liveliness, LivelinessPolicy.AUTOMATIC).name,
            "deadline": duration_ns(self.deadline),
            "lifespan": duration_ns(self.lifespan),
            "liveliness_lease_duration": duration_ns(self.liveliness_lease_duration),
        }

    @property
    def keeps_history(self) -> bool:
        """Whether messages are kept for late subscribers."""
        return self.durability is DurabilityPolicy.TRANSIENT_LOCAL


_VAGUE = ("SYSTEM_DEFAULT", "UNKNOWN")


def _in_force(policy: _PolicyEnum, default: _PolicyEnum) -> _PolicyEnum:
    """What a ROS 2 middleware uses for a ``SYSTEM_DEFAULT``/``UNKNOWN`` policy."""
    return default if policy.name in _VAGUE else policy


def _profile(**kwargs: Any) -> QoSProfile:
    return QoSProfile(**kwargs)


_SYSTEM = {
    "history": HistoryPolicy.SYSTEM_DEFAULT,
    "depth": 0,
    "reliability": ReliabilityPolicy.SYSTEM_DEFAULT,
    "durability": DurabilityPolicy.SYSTEM_DEFAULT,
    "liveliness": LivelinessPolicy.SYSTEM_DEFAULT,
}
qos_profile_system_default = _profile(**_SYSTEM)
qos_profile_default = _profile(depth=10)
qos_profile_sensor_data = _profile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
qos_profile_services_default = _profile(depth=10)
qos_profile_parameters = _profile(depth=1000)
qos_profile_parameter_events = _profile(depth=1000)
qos_profile_action_status_default = _profile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
qos_profile_rosout_default = _profile(
    depth=1000, durability=DurabilityPolicy.TRANSIENT_LOCAL, lifespan=Duration(seconds=10)
)
qos_profile_unknown = _profile(
    history=HistoryPolicy.UNKNOWN, depth=0, reliability=ReliabilityPolicy.UNKNOWN,
    durability=DurabilityPolicy.UNKNOWN, liveliness=LivelinessPolicy.UNKNOWN,
)  # fmt: skip
qos_profile_best_available = _profile(
    depth=10, reliability=ReliabilityPolicy.BEST_AVAILABLE,
    durability=DurabilityPolicy.BEST_AVAILABLE, liveliness=LivelinessPolicy.BEST_AVAILABLE,
)  # fmt: skip


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
    BEST_AVAILABLE = qos_profile_best_available

    @classmethod
    def short_keys(cls) -> list[str]:
        """The lowercase names (``sensor_data``...)."""
        return [name.lower() for name in cls.__members__]

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
