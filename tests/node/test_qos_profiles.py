"""QoS profiles, policy enums, presets and rmw's compatibility rules (rclpy.qos's names)."""

from __future__ import annotations

import pytest

from rosl.node.clock import Duration
from rosl.node.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    InvalidQoSProfileException,
    LivelinessPolicy,
    QoSPolicyKind,
    QoSPresetProfiles,
    QoSProfile,
    QoSReliabilityPolicy,
    ReliabilityPolicy,
    qos_policy_name_from_kind,
    qos_profile_action_status_default,
    qos_profile_parameters,
    qos_profile_sensor_data,
    qos_profile_system_default,
)
from rosl.node.qos_compatibility import QoSCompatibility, mismatches, qos_check_compatible


def test_presets_hold_rmw_s_policies():
    assert (qos_profile_sensor_data.depth, qos_profile_sensor_data.reliability) == (
        5, ReliabilityPolicy.BEST_EFFORT,
    )  # fmt: skip
    assert qos_profile_system_default.reliability is ReliabilityPolicy.SYSTEM_DEFAULT
    assert qos_profile_system_default.history is HistoryPolicy.SYSTEM_DEFAULT
    assert qos_profile_parameters.depth == 1000
    assert qos_profile_action_status_default.durability is DurabilityPolicy.TRANSIENT_LOCAL
    sensor = QoSPresetProfiles.get_from_short_key("SENSOR_data")
    assert sensor == qos_profile_sensor_data
    assert sensor is not qos_profile_sensor_data
    assert "parameter_events" in QoSPresetProfiles.short_keys()


def test_policy_enums_have_short_keys_old_names_and_deprecated_rmw_aliases():
    assert QoSReliabilityPolicy is ReliabilityPolicy
    assert ReliabilityPolicy.get_from_short_key("best_effort") == 2
    assert LivelinessPolicy.MANUAL_BY_TOPIC.short_key == "manual_by_topic"
    with pytest.warns(DeprecationWarning, match="RMW_QOS_POLICY_RELIABILITY_RELIABLE"):
        assert ReliabilityPolicy.RMW_QOS_POLICY_RELIABILITY_RELIABLE is ReliabilityPolicy.RELIABLE
    assert int(QoSPolicyKind.RELIABILITY) == 16
    assert qos_policy_name_from_kind(1 << 2) == "DEADLINE"


def test_a_profile_holds_durations_and_refuses_what_makes_no_profile():
    qos = QoSProfile(depth=1, deadline=Duration(seconds=0.5))
    assert qos.deadline.nanoseconds == 500_000_000
    assert qos.lifespan == Duration()  # rmw's default: none (infinite)
    assert qos.words()["deadline"] == 500_000_000
    assert qos.words()["lifespan"] == 0
    assert QoSProfile(depth=1, lifespan=Duration.max()).words()["lifespan"] == 0
    with pytest.raises(InvalidQoSProfileException, match="history and/or depth"):
        QoSProfile()
    with pytest.raises(InvalidQoSProfileException, match="deadline must be a Duration"):
        QoSProfile(depth=1, deadline=0.5)
    with pytest.raises(InvalidQoSProfileException, match="depth must be >= 0"):
        QoSProfile(depth=-1)


def _words(**settings):
    return QoSProfile(depth=10, **settings).words()


@pytest.mark.parametrize(
    ("offered", "requested", "kinds"),
    [
        ({"reliability": ReliabilityPolicy.BEST_EFFORT}, {}, ["RELIABILITY"]),
        ({}, {"reliability": ReliabilityPolicy.BEST_EFFORT}, []),
        ({}, {"durability": DurabilityPolicy.TRANSIENT_LOCAL}, ["DURABILITY"]),
        ({"durability": DurabilityPolicy.TRANSIENT_LOCAL}, {}, []),
        ({}, {"deadline": Duration(seconds=1)}, ["DEADLINE"]),
        ({"deadline": Duration(seconds=2)}, {"deadline": Duration(seconds=1)}, ["DEADLINE"]),
        ({"deadline": Duration(seconds=1)}, {"deadline": Duration(seconds=2)}, []),
        ({}, {"liveliness": LivelinessPolicy.MANUAL_BY_TOPIC}, ["LIVELINESS"]),
        ({"liveliness": LivelinessPolicy.MANUAL_BY_TOPIC}, {}, []),
        ({"liveliness": LivelinessPolicy.MANUAL_BY_NODE},
         {"liveliness": LivelinessPolicy.MANUAL_BY_TOPIC}, ["LIVELINESS"]),
        ({"liveliness": LivelinessPolicy.MANUAL_BY_TOPIC},
         {"liveliness": LivelinessPolicy.MANUAL_BY_NODE}, []),
        ({}, {"liveliness_lease_duration": Duration(seconds=1)}, ["LIVELINESS_LEASE_DURATION"]),
        ({"reliability": ReliabilityPolicy.BEST_AVAILABLE}, {}, []),
        ({"reliability": ReliabilityPolicy.BEST_EFFORT},
         {"reliability": ReliabilityPolicy.BEST_AVAILABLE}, []),
        ({"reliability": ReliabilityPolicy.BEST_EFFORT},
         {"durability": DurabilityPolicy.TRANSIENT_LOCAL}, ["DURABILITY", "RELIABILITY"]),
    ],
)  # fmt: skip
def test_rmw_s_rules_decide_which_pairs_match(offered, requested, kinds):
    found = mismatches(_words(**offered), _words(**requested))
    assert [m.kind.name for m in found] == kinds


def test_qos_check_compatible_answers_as_rclpy():
    best_effort = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)
    verdict, reason = qos_check_compatible(best_effort, QoSProfile(depth=1))
    assert verdict is QoSCompatibility.ERROR
    assert "best-effort publisher and reliable subscription" in reason
    assert qos_check_compatible(QoSProfile(depth=1), best_effort) == (QoSCompatibility.OK, "")
    verdict, _ = qos_check_compatible(qos_profile_system_default, QoSProfile(depth=1))
    assert verdict is QoSCompatibility.WARNING


def test_a_system_default_subscription_hears_a_best_effort_publisher_as_with_dds():
    """DDS readers default to best effort: the seed's obstacle avoidance reads a sensor topic."""
    publisher = qos_profile_sensor_data.words()
    subscription = qos_profile_system_default.words(subscription=True)

    assert subscription["reliability"] == "BEST_EFFORT"
    assert mismatches(publisher, subscription) == []
    assert qos_profile_system_default.words()["reliability"] == "RELIABLE"  # a publisher's
    verdict, _ = qos_check_compatible(qos_profile_sensor_data, qos_profile_system_default)
    assert verdict is not QoSCompatibility.ERROR
