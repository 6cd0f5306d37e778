"""The shipped interfaces/ define exactly what ROS 2 Humble defines (proved against rosbags)."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.typesys import Stores, get_typestore

from rosl.idl import registry
from rosl.idl.store import typesdict_entry
from rosl.resources import shipped_dir

INTERFACES = shipped_dir("interfaces")
HUMBLE = get_typestore(Stores.ROS2_HUMBLE)
JAZZY = get_typestore(Stores.ROS2_JAZZY)
REQUIRED_PACKAGES = [
    "builtin_interfaces",
    "std_msgs",
    "geometry_msgs",
    "sensor_msgs",
    "nav_msgs",
    "tf2_msgs",
    "std_srvs",
    "rcl_interfaces",
    "rosgraph_msgs",
    "diagnostic_msgs",
    "visualization_msgs",
    "trajectory_msgs",
    "shape_msgs",
    "action_msgs",
    "unique_identifier_msgs",
    "lifecycle_msgs",
    "statistics_msgs",
]
REQUIRED_SERVICES = [
    "std_srvs/srv/Empty",
    "std_srvs/srv/Trigger",
    "std_srvs/srv/SetBool",
    "rcl_interfaces/srv/GetParameters",
    "rcl_interfaces/srv/SetParameters",
    "rcl_interfaces/srv/SetParametersAtomically",
    "rcl_interfaces/srv/ListParameters",
    "rcl_interfaces/srv/DescribeParameters",
    "rcl_interfaces/srv/GetParameterTypes",
]


OWN_PACKAGES = {"rosl_msgs"}  # rosl's own interfaces, not ROS 2's


def shipped(kind: str) -> list[str]:
    return sorted(
        f"{path.parent.parent.name}/{kind}/{path.stem}"
        for path in INTERFACES.glob(f"*/{kind}/*.{kind}")
        if path.parent.parent.name not in OWN_PACKAGES
    )


# rosbags has no example_interfaces: tests/idl/test_example_interfaces.py checks its messages
MESSAGES = [m for m in shipped("msg") if not m.startswith("example_interfaces/")]
SERVICES = shipped("srv")
ACTIONS = shipped("action")


def reference(type_name: str):
    store = HUMBLE if type_name in HUMBLE.fielddefs else JAZZY
    return store


@pytest.mark.parametrize("type_name", MESSAGES)
def test_shipped_message_has_exactly_the_ros2_definition(type_name):
    store = reference(type_name)
    assert type_name in store.fielddefs, f"{type_name} is in neither Humble nor Jazzy"
    registry.get_message_class(type_name)
    spec = registry.resolve(registry.load_spec(type_name))
    constants, fields = typesdict_entry(spec)
    ref_constants, ref_fields = store.fielddefs[type_name]
    assert [tuple(c) for c in constants] == [tuple(c) for c in ref_constants]
    assert [(n, d) for n, d in fields] == [(n, d) for n, d in ref_fields]
    for ours, theirs in zip(constants, ref_constants, strict=True):
        assert type(ours[2]) is type(theirs[2]), ours
    assert registry.store().type_hash(type_name) == store.hash_rihs01(type_name)


def test_every_humble_message_of_the_required_packages_is_shipped():
    wanted = {n for n in HUMBLE.fielddefs if n.split("/")[0] in REQUIRED_PACKAGES}
    assert wanted <= set(MESSAGES)


@pytest.mark.parametrize("type_name", REQUIRED_SERVICES)
def test_required_services_are_shipped(type_name):
    assert type_name in SERVICES


@pytest.mark.parametrize("type_name", SERVICES)
def test_shipped_service_parses_and_resolves(type_name):
    service = registry.get_service_class(type_name)
    assert service.Request.__msgtype__ == f"{type_name}_Request"
    store = registry.store()
    for half in (service.Request(), service.Response()):
        data = store.serialize(half)
        assert store.deserialize(data, half.__msgtype__) == half


@pytest.mark.parametrize("type_name", ACTIONS)
def test_shipped_action_parses_and_its_generated_types_round_trip(type_name):
    action = registry.get_action_class(type_name)
    impl = action.Impl
    store = registry.store()
    for message in (
        action.Goal(), action.Result(), action.Feedback(), impl.FeedbackMessage(),
        impl.SendGoalService.Request(), impl.SendGoalService.Response(),
        impl.GetResultService.Request(), impl.GetResultService.Response(),
    ):  # fmt: skip
        assert store.deserialize(store.serialize(message), message.__msgtype__) == message


def test_parameter_service_fields_match_ros2():
    get = registry.get_service_class("rcl_interfaces/srv/GetParameters")
    assert get.Request._fields == ("names",)
    assert get.Response._fields == ("values",)
    trigger = registry.get_service_class("std_srvs/srv/Trigger")
    assert trigger.Request._fields == ()
    assert trigger.Response._fields == ("success", "message")


def test_shipped_files_carry_our_own_header_comment():
    for path in sorted(INTERFACES.glob("*/*/*.*")):
        if path.suffix in (".msg", ".srv", ".action"):
            first = path.read_text().splitlines()[0]
            assert first.startswith("#"), path


def test_every_shipped_package_xml_names_its_folder():
    for manifest in INTERFACES.glob("*/package.xml"):
        assert f"<name>{manifest.parent.name}</name>" in manifest.read_text()


def test_shipped_folder_is_the_checkout_in_an_editable_install():
    assert (Path(INTERFACES) / "std_msgs" / "msg" / "String.msg").is_file()


def test_rosl_own_messages_load_and_round_trip():
    ack_type = registry.get_message_class("rosl_msgs/msg/LockstepAck")
    ack = ack_type(source=7, endpoints=[1, 2], seqs=[10, 20], next_wakeup=-1)
    store = registry.store()
    assert store.deserialize(store.serialize(ack), "rosl_msgs/msg/LockstepAck") == ack
