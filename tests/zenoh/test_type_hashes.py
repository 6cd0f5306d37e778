"""RIHS01 type hashes: rosl's must be ROS 2's, or no rmw_zenoh node matches rosl's keys.

Goldens come from rmw_zenoh's docs/design.md (std_msgs/String, example_interfaces/AddTwoInts,
a service whose hash covers service_msgs/ServiceEventInfo's ``char[16]``). Every message type
shipped in interfaces/ is compared with rosbags' own ROS 2 store where rosbags has the type and
none of its fields is ``char`` (rosbags hashes ``char`` as FIELD_TYPE_CHAR; rosidl first turns a
.msg ``char`` into ``uint8``, which the AddTwoInts golden proves).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.typesys import Stores, get_typestore

from rosl.idl import registry

INTERFACES = Path(__file__).resolve().parents[2] / "interfaces"
MESSAGES = sorted(
    f"{path.parents[1].name}/msg/{path.stem}" for path in INTERFACES.glob("*/msg/*.msg")
)
SERVICES = sorted(
    f"{path.parents[1].name}/srv/{path.stem}" for path in INTERFACES.glob("*/srv/*.srv")
)


# interfaces/ holds Humble's definitions; Jazzy added `float32 variance` to Range, so its hash
# (and so its rmw_zenoh key) differs from Jazzy's and Kilted's
NEWER_IN_JAZZY = ["sensor_msgs/msg/Range"]


def _hash(type_name: str) -> str:
    registry.get_message_class(type_name)
    return registry.store().ros2_type_hash(type_name)


def _service_hash(type_name: str) -> str:
    registry.get_service_class(type_name)
    registry.get_message_class(f"{type_name}_Event")
    return registry.store().service_type_hash(type_name)


@pytest.mark.parametrize(
    ("type_name", "expected"),
    [
        ("std_msgs/msg/String",
         "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"),
        ("geometry_msgs/msg/TwistStamped",
         "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64"),
    ],
)  # fmt: skip
def test_message_hashes_equal_the_design_documents(type_name: str, expected: str) -> None:
    assert _hash(type_name) == expected


def test_a_service_hash_covers_request_response_and_event_with_char_as_uint8() -> None:
    assert _service_hash("example_interfaces/srv/AddTwoInts") == (
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
    )


def _uses_char(store: object, type_name: str, seen: set[str] | None = None) -> bool:
    seen = set() if seen is None else seen
    if type_name in seen:
        return False
    seen.add(type_name)
    for _, desc in store.fielddefs[type_name][1]:  # type: ignore[attr-defined]
        inner = desc[1][0] if desc[0] in (3, 4) else desc
        if inner[0] == 1 and inner[1][0] == "char":
            return True
        if inner[0] == 2 and _uses_char(store, inner[1], seen):
            return True
    return False


@pytest.mark.parametrize("distro", [Stores.ROS2_JAZZY, Stores.ROS2_KILTED])
def test_every_shipped_message_hashes_as_rosbags_ros2_store_does(distro: Stores) -> None:
    reference = get_typestore(distro)
    compared, differ = 0, []
    for type_name in MESSAGES:
        if type_name not in reference.fielddefs or _uses_char(reference, type_name):
            continue
        compared += 1
        if _hash(type_name) != reference.hash_rihs01(type_name):
            differ.append(type_name)
    assert compared > 100
    assert differ == NEWER_IN_JAZZY


def test_every_shipped_type_and_service_has_a_rihs01_hash() -> None:
    hashes = [_hash(t) for t in MESSAGES] + [_service_hash(t) for t in SERVICES]
    assert len(hashes) == len(MESSAGES) + len(SERVICES) > 150
    assert all(h.startswith("RIHS01_") and len(h) == 71 for h in hashes)
