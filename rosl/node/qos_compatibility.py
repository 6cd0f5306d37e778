"""Whether a publisher and a subscription match: rmw's QoS compatibility rules.

A subscription takes nothing from a publisher that offers less than it requests:

* a best-effort publisher and a reliable subscription (RELIABILITY);
* a volatile publisher and a transient-local subscription (DURABILITY);
* a publisher's deadline longer than the subscription's, or none where it asks for one
  (DEADLINE);
* an automatic publisher and a manual subscription, or manual-by-node and manual-by-topic
  (LIVELINESS);
* a lease longer than the subscription's, or none where it asks for one
  (LIVELINESS_LEASE_DURATION).

The rules read QoS *words* (:meth:`QoSProfile.words`, as discovery announces them), so both
sides decide from the same data. ``BEST_AVAILABLE`` offers the strongest policy on a publisher
and asks the weakest on a subscription (it matches everything, as in Jazzy).
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any, NamedTuple

from rosl.node.qos import QoSPolicyKind

if TYPE_CHECKING:
    from collections.abc import Mapping

    from rosl.node.qos import QoSProfile

_VAGUE = ("SYSTEM_DEFAULT", "UNKNOWN")


class QoSCompatibility(enum.IntEnum):
    """rclpy's answer to ``qos_check_compatible``."""

    OK = 0
    WARNING = 1
    ERROR = 2


class Mismatch(NamedTuple):
    """One policy on which a publisher offers less than a subscription requests."""

    kind: QoSPolicyKind
    reason: str


_LIVELINESS = {"AUTOMATIC": 1, "MANUAL_BY_NODE": 2, "MANUAL_BY_TOPIC": 3}  # rmw's order


def _word(words: Mapping[str, Any], key: str) -> str:
    return str(words.get(key, "")).lower().replace("_", "-")


def _ns(words: Mapping[str, Any], key: str) -> int:
    try:
        return max(0, int(words.get(key, 0) or 0))
    except (TypeError, ValueError):
        return 0


def mismatches(offered: Mapping[str, Any], requested: Mapping[str, Any]) -> list[Mismatch]:
    """The policies on which the publisher's words fail the subscription's (in kind order)."""
    found: list[Mismatch] = []
    if requested.get("durability") == "TRANSIENT_LOCAL" and offered.get("durability") == "VOLATILE":
        found.append(Mismatch(QoSPolicyKind.DURABILITY,
                              "volatile publisher and transient-local subscription"))  # fmt: skip
    wanted, given = _ns(requested, "deadline"), _ns(offered, "deadline")
    if wanted and (not given or given > wanted):
        what = f"{given} ns" if given else "none"
        found.append(Mismatch(QoSPolicyKind.DEADLINE,
                              f"publisher deadline ({what}) longer than the subscription's "
                              f"({wanted} ns)"))  # fmt: skip
    asked = _LIVELINESS.get(str(requested.get("liveliness")), 0)
    kept = _LIVELINESS.get(str(offered.get("liveliness")), 0)
    if asked and kept and kept < asked:
        found.append(Mismatch(QoSPolicyKind.LIVELINESS,
                              f"{_word(offered, 'liveliness')} publisher and "
                              f"{_word(requested, 'liveliness')} subscription"))  # fmt: skip
    if requested.get("reliability") == "RELIABLE" and offered.get("reliability") == "BEST_EFFORT":
        found.append(Mismatch(QoSPolicyKind.RELIABILITY,
                              "best-effort publisher and reliable subscription"))  # fmt: skip
    wanted, given = (
        _ns(requested, "liveliness_lease_duration"),
        _ns(offered, "liveliness_lease_duration"),
    )
    if wanted and (not given or given > wanted):
        what = f"{given} ns" if given else "none"
        found.append(Mismatch(QoSPolicyKind.LIVELINESS_LEASE_DURATION,
                              f"publisher lease ({what}) longer than the subscription's "
                              f"({wanted} ns)"))  # fmt: skip
    return found


def compatible(offered: Mapping[str, Any], requested: Mapping[str, Any]) -> bool:
    """Whether a publisher with QoS words ``offered`` delivers to ``requested``."""
    return not mismatches(offered, requested)


def qos_check_compatible(
    publisher_qos: QoSProfile, subscription_qos: QoSProfile
) -> tuple[QoSCompatibility, str]:
    """Check as rclpy does: ERROR when they cannot match, WARNING when that depends on defaults.

    Returns:
        The verdict and the reason (empty when OK).
    """
    found = mismatches(publisher_qos.words(), subscription_qos.words(subscription=True))
    if found:
        return QoSCompatibility.ERROR, "; ".join(m.reason for m in found)
    vague = [
        name
        for name in ("reliability", "durability", "liveliness")
        if getattr(publisher_qos, name).name in _VAGUE
        or getattr(subscription_qos, name).name in _VAGUE
    ]
    if vague:
        return QoSCompatibility.WARNING, (
            f"{', '.join(vague)} left to the system default: compatibility depends on it"
        )
    return QoSCompatibility.OK, ""
