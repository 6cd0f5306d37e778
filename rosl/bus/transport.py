"""The transport seam: what node/ and graph/ need from a bus, and which bus a process gets.

A :class:`Transport` sends datagrams on numbered channels and makes :class:`Receiver` s. A
receiver joins and leaves channels and owns its receive loop: ``poll`` waits (bounded by its
timeout, cut short by ``wake``) and returns whole :class:`~rosl.bus.wire.Delivery` records —
reassembly, early filtering and loss accounting happen inside, in the receiver's
:class:`~rosl.bus.wire.Reader`. Nothing above bus/ sees a socket, a file descriptor or
``select``. Channel 0 carries discovery; a topic or service travels on
:func:`channel_of` its hash.

Implementations: :class:`rosl.bus.multicast.MulticastTransport` (UDP multicast, the default)
and :class:`rosl.bus.inprocess.InProcessTransport` (one process, for tests of the seam), and
:class:`rosl.bus.zenoh_transport.ZenohTransport` (Zenoh in rmw_zenoh's wire format: ROS 2
nodes, other hosts). The environment variable ``ROSL_TRANSPORT`` picks one (``multicast``,
``inprocess``, ``zenoh``). A transport may also have ``register_writer(topic, name, type,
kind)``, called for every new writer: the Zenoh transport learns its key expression there;
and ``direct_sender(topic, sender, endpoint, kind)``, which may return a function
``(payload, seq, stamp)`` that a writer of an unsigned transport calls for its plain messages
instead of making a datagram (the Zenoh transport's puts); ``datagram_sender(channel)``,
which returns ``send(channel, [datagram])`` for one channel as a function of the datagram
with its look-ups done once (the multicast transport's, for a writer's small messages); and
``shm`` (a :class:`rosl.bus.shm.SharedMemory`, or None): the multicast transport's rings for
large messages between processes of one host (writers opt in with ``use_shm``).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Protocol

from rosl.bus.errors import BusError

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from rosl.bus.auth import Auth
    from rosl.bus.pacing import Pacer
    from rosl.bus.wire import Delivery, Reader

Buffer = bytes | bytearray | memoryview
CHANNELS = 64  # data channels per domain (1..CHANNELS); channel 0 is discovery
TRANSPORTS = ("multicast", "inprocess", "zenoh")


class Receiver(Protocol):
    """One receive loop: the channels it joined, whole deliveries out."""

    reader: Reader  # reassembly, topic filter, per-publisher sequence and loss counts

    def join(self, channel: int) -> None:
        """Start receiving ``channel`` (idempotent)."""

    def leave(self, channel: int) -> None:
        """Stop receiving ``channel`` (idempotent)."""

    def poll(
        self,
        timeout: float | None,
        out: list[Delivery],
        channel: int | None = None,
        limits: Mapping[int, int] | None = None,
    ) -> int:
        """Wait up to ``timeout`` seconds, then append every complete message to ``out``.

        Args:
            timeout: seconds to wait for a first datagram (None: until one or a wake-up).
            out: receives the deliveries, in arrival order per channel.
            channel: read only this channel, and do not take wake-ups (a nested wait).
            limits: per channel, about how many datagrams one poll should take (the room in
                the queues they go to); the rest waits in the transport's own buffer, unless
                it has waited too long (see :mod:`rosl.bus.multicast`). A receiver whose
                messages are queued elsewhere anyway may ignore it.

        Returns:
            How many channels had datagrams (callers sort across channels when > 1).
        """

    def wake(self) -> None:
        """Make a blocked (or the next) :meth:`poll` return at once."""

    def close(self) -> None:
        """Leave every channel; a later poll returns nothing (idempotent)."""


class Transport(Protocol):
    """A bus for one domain: send on channels, receive through receivers."""

    name: str  # for messages to the user: "multicast"
    fix_hint: str  # what to check when a process never hears its own datagrams
    domain: int
    max_datagram: int  # the largest datagram send() takes, header included
    pacer: Pacer  # paces fragmented messages so receivers keep up
    auth: Auth | None  # the domain key datagrams are signed and checked with (None: off)

    def send(self, channel: int, parts: Sequence[Buffer]) -> None:
        """Send one datagram made of ``parts`` to every receiver of ``channel``."""

    def receiver(self) -> Receiver:
        """A new receiver with no channel joined."""

    def describe(self) -> str:
        """Where the traffic goes, for messages (``239.255.5.0:17405 via 127.0.0.1``)."""

    def close(self) -> None:
        """Close the sender and every receiver (idempotent)."""


def channel_of(topic_hash: int) -> int:
    """The data channel (1..CHANNELS) a topic or service hash travels on."""
    return 1 + topic_hash % CHANNELS


def open_transport(domain: int | str | None = None) -> Transport:
    """The transport ``ROSL_TRANSPORT`` names (multicast by default) on a domain.

    Raises:
        BusError: an unknown transport name, a bad domain id, or a bus that cannot be opened.
    """
    name = os.environ.get("ROSL_TRANSPORT", "").strip().lower() or "multicast"
    if name == "multicast":
        from rosl.bus.multicast import MulticastTransport, addressing_from_env

        return MulticastTransport(addressing_from_env(domain))
    if name == "inprocess":
        from rosl.bus.inprocess import InProcessTransport
        from rosl.bus.multicast import domain_from_env

        return InProcessTransport(domain_from_env(domain))
    if name == "zenoh":
        from rosl.bus.multicast import domain_from_env
        from rosl.bus.zenoh_transport import ZenohTransport

        return ZenohTransport(domain_from_env(domain))
    raise BusError(f"ROSL_TRANSPORT={name!r} is not a transport (one of: {', '.join(TRANSPORTS)})")
