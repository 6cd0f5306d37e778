"""An rmw_zenoh node written with the plain ``zenoh`` API only (no rosl import).

Written from ros2/rmw_zenoh's docs/design.md, as a ROS 2 node on rmw_zenoh_cpp would behave:
liveliness tokens for its node and endpoint, puts with the 33-byte attachment, CDR payloads
with their encapsulation header, services as a complete queryable answered to gets.

    python peer.py talker|listener|server|client PORT DOMAIN [a b]
    python peer.py latched_talker|latched_listener PORT DOMAIN
    python peer.py humble_talker PORT DOMAIN
    python peer.py gappy_talker PORT DOMAIN

``humble_talker`` is the talker as ROS 2 Humble's rmw_zenoh names it: ``TypeHashNotSupported``
where the type hash goes, in its key expression and its token. ``gappy_talker`` waits for a
subscriber, then sends sequence numbers 1, 2, 3, 6, 7 and 7 again (two lost, one duplicate).

``latched_*`` are transient-local with depth 3, as rmw_zenoh declares them: the talker an
``AdvancedPublisher`` caching 3 samples with publisher detection (it publishes
``Latched: 1`` to ``Latched: 5`` on ``/latched`` once, then waits), the listener an
``AdvancedSubscriber`` whose history detects late publishers.

It connects to the router at tcp/127.0.0.1:PORT with multicast scouting off, and prints one
line per thing it saw (``heard ...``, ``served ...``, ``sum ...``) for the tests to read.
"""

from __future__ import annotations

import struct
import sys
import time

import xxhash
import zenoh

STRING = "std_msgs::msg::dds_::String_"
STRING_HASH = "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
ADD = "example_interfaces::srv::dds_::AddTwoInts_"
ADD_HASH = "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
QOS = "::,10:,:,:,,"  # reliable, volatile, keep last 10
LATCHED_QOS = ":1:,3:,:,:,,"  # reliable, transient local, keep last 3
CDR_LE = b"\x00\x01\x00\x00"


def gid(token: str) -> bytes:
    return xxhash.xxh3_128_intdigest(token.encode()).to_bytes(16, "little")


def attachment(seq: int, stamp: int, source: bytes) -> bytes:
    return struct.pack("<qq", seq, stamp) + bytes([16]) + source


def string_cdr(text: str) -> bytes:
    raw = text.encode() + b"\x00"
    return CDR_LE + struct.pack("<I", len(raw)) + raw


def read_string(cdr: bytes) -> str:
    (length,) = struct.unpack_from("<I", cdr, 4)
    return cdr[8 : 8 + length - 1].decode()


def main() -> None:
    role, port, domain = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("connect/endpoints", f'["tcp/127.0.0.1:{port}"]')
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("transport/shared_memory/enabled", "false")  # rmw_zenoh's default
    session = zenoh.open(config)
    zid = str(session.info.zid())
    node = {
        "talker": "talker",
        "listener": "listener",
        "server": "add_two_ints_server",
        "client": "add_two_ints_client",
        "latched_talker": "latched_talker",
        "latched_listener": "latched_listener",
        "humble_talker": "talker",
        "gappy_talker": "talker",
    }[role]
    prefix = f"@ros2_lv/{domain}/{zid}/0"
    tokens = [session.liveliness().declare_token(f"{prefix}/0/NN/%/%/{node}")]
    if role.startswith("latched_"):
        kind = "MP" if role == "latched_talker" else "MS"
        token = f"{prefix}/10/{kind}/%/%/{node}/%latched/{STRING}/{STRING_HASH}/{LATCHED_QOS}"
        key = f"{domain}/latched/{STRING}/{STRING_HASH}"
    elif role == "humble_talker":
        token = f"{prefix}/10/MP/%/%/{node}/%chatter/{STRING}/TypeHashNotSupported/{QOS}"
        key = f"{domain}/chatter/{STRING}/TypeHashNotSupported"
    elif role in ("talker", "listener", "gappy_talker"):
        kind = "MS" if role == "listener" else "MP"
        token = f"{prefix}/10/{kind}/%/%/{node}/%chatter/{STRING}/{STRING_HASH}/{QOS}"
        key = f"{domain}/chatter/{STRING}/{STRING_HASH}"
    else:
        kind = "SS" if role == "server" else "SC"
        token = f"{prefix}/10/{kind}/%/%/{node}/%add_two_ints/{ADD}/{ADD_HASH}/{QOS}"
        key = f"{domain}/add_two_ints/{ADD}/{ADD_HASH}"
    tokens.append(session.liveliness().declare_token(token))
    me = gid(token)
    if role.startswith("latched_"):
        latched(session, role, key, me, zid)
        return
    print(f"ready {zid}", flush=True)
    if role == "gappy_talker":
        publisher = session.declare_publisher(key)
        while not publisher.matching_status:
            time.sleep(0.05)
        time.sleep(0.5)  # every subscriber of the router's graph has its route by now
        for seq in (1, 2, 3, 6, 7, 7):
            publisher.put(string_cdr(f"m{seq}"), attachment=attachment(seq, time.time_ns(), me))
        while True:
            time.sleep(1)
    if role in ("talker", "humble_talker"):
        publisher = session.declare_publisher(key)
        seq = 0
        while True:
            seq += 1
            publisher.put(
                string_cdr(f"Hello World: {seq}"), attachment=attachment(seq, time.time_ns(), me)
            )
            time.sleep(0.1)
    elif role == "listener":

        def heard(sample: zenoh.Sample) -> None:
            if sample.attachment is None:
                return
            raw = sample.attachment.to_bytes()
            seq, _stamp = struct.unpack_from("<qq", raw)
            print(
                f"heard {read_string(sample.payload.to_bytes())!r} seq={seq} "
                f"gidlen={raw[16]} size={len(raw)}",
                flush=True,
            )

        subscriber = session.declare_subscriber(key, heard)
        del subscriber
        while True:
            time.sleep(1)
    elif role == "server":

        def serve(query: zenoh.Query) -> None:
            raw = query.attachment.to_bytes()
            seq, _stamp = struct.unpack_from("<qq", raw)
            a, b = struct.unpack_from("<qq", query.payload.to_bytes(), 4)
            print(f"served {a}+{b} seq={seq}", flush=True)
            body = CDR_LE + struct.pack("<q", a + b)
            query.reply(
                query.key_expr, body, attachment=attachment(seq, time.time_ns(), raw[17:33])
            )

        queryable = session.declare_queryable(key, serve, complete=True)
        del queryable
        while True:
            time.sleep(1)
    else:
        a, b = int(sys.argv[4]), int(sys.argv[5])
        for attempt in range(1, 100):
            request = CDR_LE + struct.pack("<qq", a, b)
            replies = session.get(
                key,
                target=zenoh.QueryTarget.ALL_COMPLETE,
                payload=request,
                timeout=2.0,
                attachment=attachment(attempt, time.time_ns(), me),
            )
            for reply in replies:
                if reply.ok is not None:
                    raw = reply.ok.attachment.to_bytes()
                    (total,) = struct.unpack_from("<q", reply.ok.payload.to_bytes(), 4)
                    (seq,) = struct.unpack_from("<q", raw)
                    print(f"sum {total} seq={seq} mine={raw[17:33] == me}", flush=True)
                    return
            time.sleep(0.3)
        print("no server", flush=True)


def latched(session: zenoh.Session, role: str, key: str, me: bytes, zid: str) -> None:
    """The transient-local roles (see the module docstring)."""
    from zenoh import ext

    if role == "latched_talker":
        publisher = ext.declare_advanced_publisher(
            session, key, cache=ext.CacheConfig(max_samples=3), publisher_detection=True,
            sample_miss_detection=ext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=1.0),
        )  # fmt: skip
        for seq in range(1, 6):
            publisher.put(
                string_cdr(f"Latched: {seq}"), attachment=attachment(seq, time.time_ns(), me)
            )
        print(f"ready {zid}", flush=True)
        while True:
            time.sleep(1)

    def heard(sample: zenoh.Sample) -> None:
        if sample.attachment is not None:
            print(f"heard {read_string(sample.payload.to_bytes())!r}", flush=True)

    _subscriber = ext.declare_advanced_subscriber(  # kept until the process ends
        session, key, heard, subscriber_detection=True,
        history=ext.HistoryConfig(detect_late_publishers=True, max_samples=3),
        recovery=ext.RecoveryConfig(heartbeat=True),
    )  # fmt: skip
    print(f"ready {zid}", flush=True)
    while True:
        time.sleep(1)


if __name__ == "__main__":
    main()
