"""rmw_zenoh's wire format, byte for byte, from its docs/design.md and liveliness_utils.cpp.

The goldens are the design document's examples (demo_nodes_cpp's talker and listener,
example_interfaces' add_two_ints server and client); the attachment layout is the one the
design document spells out (int64 LE sequence, int64 LE time, one byte 16, 16 GID bytes).
"""

from __future__ import annotations

import pytest

from rosl.bus import zenoh_wire as wire

STRING = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
ADD = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
LISTENER_NODE = "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
LISTENER_SUB = (
    "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/"
    f"std_msgs::msg::dds_::String_/{STRING}/::,10:,:,:,,"
)
TALKER_PUB = (
    "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/"
    f"std_msgs::msg::dds_::String_/{STRING}/::,7:,:,:,,"
)
SERVER = (
    "@ros2_lv/2/f9980ee0495eaafb3e38f0d19e2eae12/0/10/SS/%/%/add_two_ints_server/"
    f"%add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD}/::,10:,:,:,,"
)
CLIENT = (
    "@ros2_lv/2/e1dc8d1b45ae8717fce78689cc655685/0/10/SC/%/%/add_two_ints_client/"
    f"%add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD}/::,10:,:,:,,"
)


def _endpoint(zid: str, kind: str, node: str, name: str, type_: str, digest: str,
              depth: int) -> wire.Entity:  # fmt: skip
    return wire.Entity(2, zid, "0", "10", kind, "/", "/", node, name, type_, digest,
                       wire.Qos(depth=depth))  # fmt: skip


def test_data_keys_match_the_design_document() -> None:
    assert wire.topic_key(0, "/chatter", "std_msgs/msg/String", STRING) == (
        f"0/chatter/std_msgs::msg::dds_::String_/{STRING}"
    )
    assert wire.topic_key(0, "/robot1/chatter", "std_msgs/msg/String", STRING) == (
        f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING}"
    )
    assert wire.topic_key(2, "/add_two_ints", "example_interfaces/srv/AddTwoInts", ADD) == (
        f"2/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/{ADD}"
    )


def test_a_humble_key_carries_type_hash_not_supported() -> None:
    key = wire.topic_key(0, "/chatter", "std_msgs/msg/String", wire.NO_TYPE_HASH)
    assert key == "0/chatter/std_msgs::msg::dds_::String_/TypeHashNotSupported"


def test_tokens_of_talker_listener_server_and_client_match_byte_for_byte() -> None:
    node = wire.Entity(2, "aac3178e146ba6f1fc6e6a4085e77f21", "0", "0", wire.NODE, "/", "/",
                       "listener")  # fmt: skip
    assert node.keyexpr == LISTENER_NODE
    assert (
        _endpoint(
            "aac3178e146ba6f1fc6e6a4085e77f21",
            wire.SUBSCRIPTION,
            "listener",
            "/chatter",
            "std_msgs/msg/String",
            STRING,
            10,
        ).keyexpr
        == LISTENER_SUB
    )
    assert (
        _endpoint(
            "8b20917502ee955ac4476e0266340d5c",
            wire.PUBLISHER,
            "talker",
            "/chatter",
            "std_msgs/msg/String",
            STRING,
            7,
        ).keyexpr
        == TALKER_PUB
    )
    assert _endpoint("f9980ee0495eaafb3e38f0d19e2eae12", wire.SERVER, "add_two_ints_server",
                     "/add_two_ints", "example_interfaces/srv/AddTwoInts", ADD,
                     10).keyexpr == SERVER  # fmt: skip
    assert _endpoint("e1dc8d1b45ae8717fce78689cc655685", wire.CLIENT, "add_two_ints_client",
                     "/add_two_ints", "example_interfaces/srv/AddTwoInts", ADD,
                     10).keyexpr == CLIENT  # fmt: skip


@pytest.mark.parametrize("token", [LISTENER_NODE, LISTENER_SUB, TALKER_PUB, SERVER, CLIENT])
def test_tokens_read_back_to_the_same_key(token: str) -> None:
    assert wire.parse_liveliness(token).keyexpr == token


def test_a_namespace_and_nested_names_are_mangled_with_percent() -> None:
    entity = wire.Entity(
        0,
        "ab",
        "3",
        "7",
        wire.PUBLISHER,
        "/",
        "/robot1/arm",
        "talker",
        "/robot1/arm/joint_states",
        "sensor_msgs/msg/JointState",
        "RIHS01_x",
    )
    assert entity.keyexpr == (
        "@ros2_lv/0/ab/3/7/MP/%/%robot1%arm/talker/%robot1%arm%joint_states/"
        "sensor_msgs::msg::dds_::JointState_/RIHS01_x/::,:,:,:,,"
    )
    back = wire.parse_liveliness(entity.keyexpr)
    assert (back.namespace, back.name) == ("/robot1/arm", "/robot1/arm/joint_states")


@pytest.mark.parametrize(
    ("qos", "text"),
    [
        (wire.Qos(), "::,:,:,:,,"),
        (wire.Qos(depth=10), "::,10:,:,:,,"),
        (wire.Qos(reliability=2, durability=1, history=2, depth=10), "2:1:2,10:,:,:,,"),
        (wire.Qos(deadline=(1, 500), lifespan=(0, 7), liveliness=3, lease=(2, 0)),
         "::,:1,500:0,7:3,2,0"),
    ],
)  # fmt: skip
def test_qos_strings_leave_rmw_zenoh_defaults_empty(qos: wire.Qos, text: str) -> None:
    assert wire.qos_string(qos) == text
    assert wire.parse_qos(text) == qos


def test_qos_words_map_to_rmw_numbers() -> None:
    words = {"reliability": "BEST_EFFORT", "durability": "TRANSIENT_LOCAL",
             "history": "KEEP_LAST", "depth": 1, "liveliness": "AUTOMATIC"}  # fmt: skip
    assert wire.qos_string(wire.Qos.from_words(words)) == "2:1:,1:,:,:,,"
    system_default = {"reliability": "SYSTEM_DEFAULT", "durability": "SYSTEM_DEFAULT",
                      "history": "SYSTEM_DEFAULT", "depth": 0}  # fmt: skip
    assert wire.Qos.from_words(system_default) == wire.Qos()  # rmw_zenoh's best available


def test_the_attachment_is_33_bytes_as_the_design_document_lays_it_out() -> None:
    gid = bytes(range(16))
    data = wire.encode_attachment(1, 0x0102030405060708, gid)
    assert data == bytes.fromhex(
        "0100000000000000080706050403020110000102030405060708090a0b0c0d0e0f"
    )
    assert wire.decode_attachment(data) == (1, 0x0102030405060708, gid)


@pytest.mark.parametrize("data", [b"", bytes(32), bytes(34), bytes(16) + b"\x0f" + bytes(16)])
def test_malformed_attachments_are_refused(data: bytes) -> None:
    with pytest.raises(ValueError, match=r"attachment|GID"):
        wire.decode_attachment(data)


def test_the_gid_is_xxh3_128_of_the_token_low_half_first() -> None:
    # XXH3-128 of nothing is 99aa06d3014798d8 6001c324468d497f (high, low)
    assert wire.gid_of("") == bytes.fromhex("7f498d4624c30160d8984701d306aa99")
    assert len(wire.gid_of(TALKER_PUB)) == 16
    assert wire.gid_of(TALKER_PUB) != wire.gid_of(LISTENER_SUB)


@pytest.mark.parametrize(
    "token",
    [
        "@ros2_lv/0/ab/0/0/NN/%/%",  # too short
        "@ros2_lv/0/ab/0/0/XX/%/%/node",  # unknown kind
        "@ros2_lv/0/ab/0/1/MP/%/%/node/%chatter",  # an endpoint without type and QoS
        "@ros2_lv/0/ab/0/1/MP/%/%/node/%chatter/std_msgs::msg::dds_::String_/h/::,",  # QoS
        "@other/0/ab/0/0/NN/%/%/node",
    ],
)
def test_malformed_tokens_are_refused(token: str) -> None:
    with pytest.raises(ValueError, match=r"token|QoS|fields|kind|component"):
        wire.parse_liveliness(token)


def test_dds_type_names_round_trip() -> None:
    assert wire.dds_type("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    assert wire.ros_type("example_interfaces::srv::dds_::AddTwoInts_") == (
        "example_interfaces/srv/AddTwoInts"
    )
    with pytest.raises(ValueError, match="DDS type"):
        wire.ros_type("std_msgs/msg/String")


def test_data_keys_read_back() -> None:
    key = wire.parse_topic_key(f"0/robot1/chatter/std_msgs::msg::dds_::String_/{STRING}")
    assert key == wire.TopicKey(0, "/robot1/chatter", "std_msgs/msg/String", STRING)


def test_a_humble_key_has_type_hash_not_supported_in_place_of_the_hash() -> None:
    key = wire.topic_key(0, "/chatter", "std_msgs/msg/String", "RIHS01_" + "ab" * 32)
    assert wire.humble_key(key) == "0/chatter/std_msgs::msg::dds_::String_/TypeHashNotSupported"
    assert wire.parse_topic_key(wire.humble_key(key)).type == "std_msgs/msg/String"
