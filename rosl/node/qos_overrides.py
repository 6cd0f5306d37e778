"""QoS overrides (rclpy.qos_overriding_options): a topic's QoS from read-only parameters.

``create_publisher(..., qos_overriding_options=QoSOverridingOptions.with_default_policies())``
declares ``qos_overrides./chatter.publisher.depth`` (and ``history``, ``reliability``) as
read-only parameters holding the profile's values; a value given with ``--ros-args -p`` or in
a parameters file replaces the profile's before the publisher exists. An ``entity_id`` tells
two publishers of one topic apart (``qos_overrides./chatter.publisher_fast.depth``); the
optional callback validates the final profile.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.node.clock import Duration
from rosl.node.errors import NodeError, ParameterAlreadyDeclaredException
from rosl.node.parameters import Descriptor
from rosl.node.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSPolicyKind,
    ReliabilityPolicy,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from rosl.node.node import Node
    from rosl.node.qos import QoSProfile

_ENUMS: dict[QoSPolicyKind, Any] = {
    QoSPolicyKind.HISTORY: HistoryPolicy,
    QoSPolicyKind.RELIABILITY: ReliabilityPolicy,
    QoSPolicyKind.DURABILITY: DurabilityPolicy,
    QoSPolicyKind.LIVELINESS: LivelinessPolicy,
}
_DURATIONS = (
    QoSPolicyKind.DEADLINE, QoSPolicyKind.LIFESPAN, QoSPolicyKind.LIVELINESS_LEASE_DURATION
)  # fmt: skip
_NOT_OVERRIDABLE = (QoSPolicyKind.INVALID, QoSPolicyKind.AVOID_ROS_NAMESPACE_CONVENTIONS)


class InvalidQosOverridesError(NodeError):
    """Overrides that make no profile, or that the options' callback refused."""


@dataclass(slots=True)
class QosCallbackResult:
    """What a validating callback may return (rclpy's, as SetParametersResult's fields)."""

    successful: bool = False
    reason: str = ""


class QoSOverridingOptions:
    """Which policies of a publisher or subscription parameters may override."""

    def __init__(
        self,
        policy_kinds: Iterable[QoSPolicyKind],
        *,
        callback: Callable[[QoSProfile], Any] | None = None,
        entity_id: str | None = None,
    ) -> None:
        """Declare ``policy_kinds`` (``callback`` returns a bool or a QosCallbackResult)."""
        self._policy_kinds = tuple(policy_kinds)
        self._callback = callback
        self._entity_id = entity_id

    @property
    def policy_kinds(self) -> tuple[QoSPolicyKind, ...]:
        """The policies that get a parameter."""
        return self._policy_kinds

    @property
    def callback(self) -> Callable[[QoSProfile], Any] | None:
        """Validates the profile once overridden (a false result refuses it)."""
        return self._callback

    @property
    def entity_id(self) -> str | None:
        """Tells apart entities of one topic."""
        return self._entity_id

    @classmethod
    def with_default_policies(
        cls,
        *,
        callback: Callable[[QoSProfile], Any] | None = None,
        entity_id: str | None = None,
    ) -> QoSOverridingOptions:
        """History, depth and reliability, as rclpy's default."""
        kinds = (QoSPolicyKind.HISTORY, QoSPolicyKind.DEPTH, QoSPolicyKind.RELIABILITY)
        return cls(kinds, callback=callback, entity_id=entity_id)


def overridden(
    node: Node, kind: str, topic: str, qos: QoSProfile, options: QoSOverridingOptions | None
) -> QoSProfile:
    """``qos`` with the overrides of ``options`` applied (``qos`` itself without options).

    Args:
        node: declares the read-only parameters.
        kind: ``publisher`` or ``subscription``.
        topic: the resolved topic name.
        qos: the profile the code asked for (left unchanged: a copy is overridden).
        options: the policies to declare, or None for none.

    Raises:
        InvalidQosOverridesError: a value that names no policy, or the callback refused.
    """
    if options is None:
        return qos
    from dataclasses import replace

    profile = replace(qos)
    suffix = "" if options.entity_id is None else f"_{options.entity_id}"
    prefix = f"qos_overrides.{topic}.{kind}{suffix}"
    for policy in options.policy_kinds:
        policy = QoSPolicyKind(policy)
        lifespan = policy is QoSPolicyKind.LIFESPAN
        if policy in _NOT_OVERRIDABLE or (kind == "subscription" and lifespan):
            continue
        name = f"{prefix}.{policy.name.lower()}"
        descriptor = Descriptor(
            description=f"{policy.name.lower()} for {kind} `{topic}` with id `{options.entity_id}`",
            read_only=True,
        )
        try:
            param = node.declare_parameter(name, _value(profile, policy), descriptor)
        except ParameterAlreadyDeclaredException:
            param = node.get_parameter(name)
        _apply(profile, policy, param.value, name)
    if options.callback is not None:
        _validate(options.callback(profile), f"{kind} `{topic}` with id `{options.entity_id}`")
    return profile


def _validate(result: Any, what: str) -> None:
    """Raise unless the callback's result (a bool or a QosCallbackResult) accepts the profile."""
    successful = getattr(result, "successful", result)
    if not successful:
        reason = getattr(result, "reason", "")
        raise InvalidQosOverridesError(
            f"Provided QoS overrides for {what}, are not valid{': ' + reason if reason else ''}"
        )


def _value(profile: QoSProfile, policy: QoSPolicyKind) -> str | int | bool:
    value = getattr(profile, policy.name.lower())
    if policy in _ENUMS:
        return str(value.name.lower())
    if policy in _DURATIONS:
        return int(value.nanoseconds)
    return bool(value) if isinstance(value, bool) else int(value)


def _apply(profile: QoSProfile, policy: QoSPolicyKind, value: Any, name: str) -> None:
    attribute = policy.name.lower()
    if policy in _ENUMS:
        enum_class = _ENUMS[policy]
        try:
            setattr(profile, attribute, enum_class[str(value).upper()])
        except KeyError:
            choices = ", ".join(k for k in enum_class.short_keys() if k != "unknown")
            raise InvalidQosOverridesError(
                f"parameter '{name}': '{value}' is no {attribute} policy (choose one of {choices})"
            ) from None
        return
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InvalidQosOverridesError(
            f"parameter '{name}' must be an integer >= 0"
            f"{' (nanoseconds)' if policy in _DURATIONS else ''}, got {value!r}"
        )
    setattr(profile, attribute, Duration(nanoseconds=value) if policy in _DURATIONS else value)
