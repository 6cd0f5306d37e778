"""Transient-local durability on Zenoh, as rmw_zenoh keeps it: publication caches and history.

rmw_zenoh (Jazzy and later) declares a transient-local publisher as a zenoh-ext
``AdvancedPublisher`` with a cache of ``depth`` samples and publisher detection (plus sporadic
heartbeats for sample-miss detection when it is reliable), and a transient-local subscription
as an ``AdvancedSubscriber`` whose history query asks those caches for their samples.

rosl does the same on the wire:

* :func:`declare_cached_publisher` makes the ``AdvancedPublisher`` a rosl transient-local
  publisher puts through, so a ROS 2 subscription (or any rosl process) that joins later is
  served from its cache;
* :func:`query_history` sends the history query of an ``AdvancedSubscriber``
  (``<key>/@adv/**`` with ``_anyke``) for one late subscription, and hands each cached sample
  back as a ``REPLAY`` addressed to that subscription alone — so the subscriptions that were
  there already get no second copy, as with rosl's own replays on the other transports.

Live samples keep arriving through the plain subscriber of the topic's key: a Zenoh
``AdvancedSubscriber`` would deliver history and live samples through one callback, with
nothing to tell them apart, and the layers above dedupe replays against live data by
(publisher, sequence number) only in that order.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.bus import zenoh_wire as wire
from rosl.bus.header import Kind

if TYPE_CHECKING:
    import zenoh

    from rosl.bus.zenoh_transport import ZenohTransport

HEARTBEAT_S = 1.0  # rmw_zenoh's sample-miss detection period (sporadic heartbeat)
QUERY_TIMEOUT_S = 10.0  # how long the caches have to answer one history query
ADVANCED = "@adv"  # zenoh-ext's key chunk for its caches and detection tokens


def declare_cached_publisher(session: zenoh.Session, key: str, depth: int, reliable: bool) -> Any:
    """An ``AdvancedPublisher`` on ``key`` caching ``depth`` samples, as rmw_zenoh declares it."""
    from zenoh import ext

    miss = (
        ext.MissDetectionConfig(heartbeat=None, sporadic_heartbeat=HEARTBEAT_S)
        if reliable
        else None
    )
    return ext.declare_advanced_publisher(
        session, key, cache=ext.CacheConfig(max_samples=max(1, depth)),
        sample_miss_detection=miss, publisher_detection=True,
    )  # fmt: skip


def history_selector(domain: int, name: str) -> str:
    """The history query of a topic: every type and type hash (Humble's too) of ``name``."""
    return f"{domain}/{name.strip('/')}/*/*/{ADVANCED}/**"


def query_history(transport: ZenohTransport, name: str, target: tuple[int, int]) -> None:
    """Ask every publication cache of topic ``name`` for its samples, for one subscription.

    Args:
        transport: the Zenoh transport of this process (its session, key hashes, the ids of
            GIDs, and where deliveries go: each cached sample becomes a ``REPLAY``).
        name: the topic, fully qualified.
        target: (process, endpoint) of the subscription the samples are for.
    """
    import zenoh

    from rosl.bus.wire import Delivery

    def on_reply(reply: zenoh.Reply) -> None:
        sample = reply.ok
        if sample is None or sample.attachment is None:
            return
        try:
            topic, type_ = transport.key_hashes(str(sample.key_expr))
            seq, stamp, gid = wire.decode_attachment(sample.attachment.to_bytes())
        except ValueError:
            return  # not a ROS 2 sample: rmw_zenoh drops it too
        sender, endpoint = transport.identity(gid)
        transport._deliver(
            Delivery(
                Kind.REPLAY,
                sender,
                endpoint,
                seq & 0xFFFFFFFF,
                topic,
                type_,
                stamp,
                time.time_ns(),
                memoryview(sample.payload.to_bytes()),
                (*target, 0),
            )
        )

    transport.session.get(
        f"{history_selector(transport.domain, name)}?_anyke", on_reply,
        target=zenoh.QueryTarget.ALL, consolidation=zenoh.ConsolidationMode.NONE,
        accept_replies=zenoh.ReplyKeyExpr.ANY, timeout=QUERY_TIMEOUT_S,
    )  # fmt: skip
