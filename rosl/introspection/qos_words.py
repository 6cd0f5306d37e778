"""The ``--qos-*`` words of ``topic pub`` and ``topic echo``, mapped onto rosl's QoS profiles.

The words and their meaning are ros2cli's (Humble): a preset profile, then each given policy
overrides it; a transient-local profile with depth 0 keeps one message. ``system_default`` and
``unknown`` policies become what a ROS 2 middleware picks for them (reliable, volatile, keep
last), so ``topic info -v`` shows the policy in force.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rosl.node.qos import QoSProfile

PROFILES = (
    "system_default",
    "sensor_data",
    "services_default",
    "parameters",
    "parameter_events",
    "action_status_default",
)
HISTORIES = ("system_default", "keep_last", "keep_all", "unknown")
RELIABILITIES = ("system_default", "reliable", "best_effort", "unknown")
DURABILITIES = ("system_default", "transient_local", "volatile", "unknown")


def given(*words: object) -> bool:
    """Whether any ``--qos-*`` option was given (``--qos-depth`` counts from 0)."""
    return any(w is not None for w in words)


def profile_from_words(
    preset: str,
    *,
    reliability: str | None = None,
    durability: str | None = None,
    depth: int | None = None,
    history: str | None = None,
) -> QoSProfile:
    """The profile ``--qos-profile PRESET --qos-reliability ...`` asks for.

    Args:
        preset: one of :data:`PROFILES` (or ``default``).
        reliability: one of :data:`RELIABILITIES`, overriding the preset's.
        durability: one of :data:`DURABILITIES`, overriding the preset's.
        depth: the history depth (a negative or missing depth keeps the preset's).
        history: one of :data:`HISTORIES`, overriding the preset's.

    Returns:
        A new profile with concrete policies.
    """
    from rosl.node.qos import (
        DurabilityPolicy,
        HistoryPolicy,
        QoSPresetProfiles,
        ReliabilityPolicy,
    )

    profile = QoSPresetProfiles.get_from_short_key(preset)
    if reliability is not None:
        profile.reliability = ReliabilityPolicy[reliability.upper()]
    if durability is not None:
        profile.durability = DurabilityPolicy[durability.upper()]
    if history is not None:
        profile.history = HistoryPolicy[history.upper()]
    if depth is not None and depth >= 0:
        profile.depth = depth
    elif profile.durability is DurabilityPolicy.TRANSIENT_LOCAL and profile.depth == 0:
        profile.depth = 1
    return _concrete(profile)


def _concrete(profile: QoSProfile) -> QoSProfile:
    """Replace ``system_default``/``unknown`` policies by what a middleware would use."""
    from rosl.node.qos import DurabilityPolicy, HistoryPolicy, ReliabilityPolicy

    vague_reliability = (ReliabilityPolicy.SYSTEM_DEFAULT, ReliabilityPolicy.UNKNOWN)
    vague_durability = (DurabilityPolicy.SYSTEM_DEFAULT, DurabilityPolicy.UNKNOWN)
    vague_history = (HistoryPolicy.SYSTEM_DEFAULT, HistoryPolicy.UNKNOWN)
    return replace(
        profile,
        reliability=ReliabilityPolicy.RELIABLE
        if profile.reliability in vague_reliability
        else profile.reliability,
        durability=DurabilityPolicy.VOLATILE
        if profile.durability in vague_durability
        else profile.durability,
        history=HistoryPolicy.KEEP_LAST if profile.history in vague_history else profile.history,
        depth=profile.depth or 10 if profile.history in vague_history else profile.depth,
    )
