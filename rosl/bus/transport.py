"""The transport seam: send a datagram on a channel, open a channel to receive.

Node, graph and bag code only talk to a :class:`Transport`. Multicast is the one built now;
a Zenoh-backed transport for reaching past one LAN would implement the same three calls.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Protocol

from rosl.bus import multicast
from rosl.bus.errors import BusError
from rosl.bus.pacing import Pacer, pacer_from_env

if TYPE_CHECKING:
    import socket
    from collections.abc import Sequence

    from rosl.bus.multicast import Addressing

Buffer = bytes | bytearray | memoryview


class Transport(Protocol):
    """What the rest of rosl needs from a transport."""

    addressing: Addressing
    max_datagram: int
    pacer: Pacer

    def send(self, channel: int, parts: Sequence[Buffer]) -> None:
        """Send one datagram made of ``parts`` to every receiver of ``channel``."""

    def open(self, channel: int) -> socket.socket:
        """Return a non-blocking socket receiving ``channel`` (shared, opened once)."""

    def close(self) -> None:
        """Close every socket."""


class MulticastTransport:
    """UDP multicast on one domain; sockets are opened lazily and shared in the process."""

    def __init__(self, addressing: Addressing) -> None:
        self.addressing = addressing
        self.max_datagram = addressing.max_datagram
        self.pacer = pacer_from_env(addressing.interface == multicast.LOOPBACK)
        self._sender = multicast.open_sender(addressing)
        self._targets = [
            (addressing.group(c), addressing.port) for c in range(multicast.CHANNELS + 1)
        ]
        self._receivers: dict[int, socket.socket] = {}
        self._lock = threading.Lock()
        self.send_errors = 0

    def send(self, channel: int, parts: Sequence[Buffer]) -> None:
        """Send one datagram; a full kernel buffer drops it (counted), never blocks."""
        target = self._targets[channel]
        try:
            if len(parts) == 1:
                self._sender.sendto(parts[0], target)
            else:
                self._sender.sendmsg(parts, (), 0, target)
        except (BlockingIOError, InterruptedError):
            self.send_errors += 1
        except OSError as err:
            if self._sender.fileno() < 0:
                return  # closed during shutdown
            raise BusError(
                f"cannot send to {target[0]}:{target[1]} ({err.strerror}); {multicast.FIX_HINT}"
            ) from None

    def open(self, channel: int) -> socket.socket:
        """Return the receiving socket of a channel, joining its group the first time."""
        with self._lock:
            sock = self._receivers.get(channel)
            if sock is None:
                sock = multicast.open_receiver(self.addressing, channel)
                self._receivers[channel] = sock
            return sock

    def close(self) -> None:
        """Close every socket (idempotent)."""
        with self._lock:
            for sock in self._receivers.values():
                sock.close()
            self._receivers.clear()
            self._sender.close()


def channel_of(topic_hash: int) -> int:
    """The data channel (1..CHANNELS) a topic or service hash travels on."""
    return 1 + topic_hash % multicast.CHANNELS
