"""The UDP multicast transport: domain → groups and port, its sockets and receive loop.

Traffic leaves through 127.0.0.1 with TTL 0 by default. See the package docstring for the
address plan, and :mod:`rosl.bus.transport` for the seam this implements. Receive buffers are
enlarged to 8 MiB where the OS allows; when it grants less than 1 MiB a single warning line
says how to raise it.
"""

from __future__ import annotations

import contextlib
import fcntl
import ipaddress
import os
import select
import socket
import struct
import sys
import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from rosl.bus import auth as keys
from rosl.bus import kernel_filter
from rosl.bus import shm as shared
from rosl.bus.errors import BusError
from rosl.bus.pacing import pacer_from_env
from rosl.bus.settings import env_number
from rosl.bus.transport import CHANNELS, channel_of
from rosl.bus.wire import Reader

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence

    from rosl.bus.auth import Auth
    from rosl.bus.transport import Buffer
    from rosl.bus.wire import Delivery

__all__ = ["CHANNELS", "Addressing", "MulticastReceiver", "MulticastTransport"]

BASE_PORT = 17400
MAX_DOMAIN = 232
RCVBUF_WANTED = 8 * 1024 * 1024
RCVBUF_WARN_BELOW = 1024 * 1024
DRAIN_LIMIT = 1024  # datagrams read from one socket per poll
BACKLOG_MS = 500  # a message that waited this long in a socket: the rest is read at once
IP_MULTICAST_ALL = 49  # linux/in.h; not exported by the socket module
LOOPBACK = "127.0.0.1"
FIX_HINT = (
    "check that the loopback interface is up (`ip link set lo up`), or set "
    "ROSL_INTERFACE to an interface that carries multicast"
)
_warned_rcvbuf = False


@dataclass(frozen=True, slots=True)
class Addressing:
    """Where one domain's traffic goes.

    Attributes:
        domain: the domain id.
        interface: the IPv4 address multicast is sent from and joined on.
        ttl: 0 keeps datagrams on this host; 1 lets them reach the local network.
    """

    domain: int
    interface: str = LOOPBACK
    ttl: int = 0

    @property
    def port(self) -> int:
        """The UDP port of this domain."""
        return BASE_PORT + self.domain

    def group(self, channel: int) -> str:
        """The multicast group of a channel (0 = discovery, 1..CHANNELS = data)."""
        return f"239.255.{self.domain}.{channel}"

    @property
    def max_datagram(self) -> int:
        """The largest datagram we send: 64 KiB on loopback, one Ethernet frame otherwise."""
        return 65000 if self.interface == LOOPBACK else 1472


def domain_from_env(value: int | str | None = None) -> int:
    """Return the domain id from ``value``, ``ROSL_DOMAIN_ID``, ``ROS_DOMAIN_ID`` or 0.

    Raises:
        BusError: not a whole number from 0 to 232.
    """
    source = "--domain-id"
    if value is None:
        for name in ("ROSL_DOMAIN_ID", "ROS_DOMAIN_ID"):
            if os.environ.get(name, "").strip():
                value, source = os.environ[name].strip(), name
                break
        else:
            return 0
    try:
        domain = int(value)
    except (TypeError, ValueError):
        raise BusError(
            f"{source}={value!r} is not a domain id (a number from 0 to {MAX_DOMAIN})"
        ) from None
    if not 0 <= domain <= MAX_DOMAIN:
        raise BusError(f"{source}={domain} is out of range: domain ids go from 0 to {MAX_DOMAIN}")
    return domain


def interface_address(name: str) -> str:
    """Return the IPv4 address of an interface given by name or address.

    Raises:
        BusError: no such interface, or it has no IPv4 address.
    """
    try:
        return str(ipaddress.IPv4Address(name))
    except ValueError:
        pass
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        packed = fcntl.ioctl(probe.fileno(), 0x8915, struct.pack("256s", name.encode()[:15]))
    except OSError as err:
        raise BusError(
            f"ROSL_INTERFACE={name}: no such interface with an IPv4 address ({err.strerror})"
        ) from None
    finally:
        probe.close()
    return socket.inet_ntoa(packed[20:24])


def addressing_from_env(domain: int | str | None = None) -> Addressing:
    """Build the addressing for this process from the environment (and an explicit domain)."""
    chosen = domain_from_env(domain)
    interface = os.environ.get("ROSL_INTERFACE", "").strip()
    if not interface:
        return Addressing(chosen)
    address = interface_address(interface)
    return Addressing(chosen, address, 0 if address.startswith("127.") else 1)


def open_sender(addressing: Addressing) -> socket.socket:
    """Open the socket all of a process's datagrams leave through."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(
            socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(addressing.interface)
        )
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, addressing.ttl)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, RCVBUF_WANTED)
    except OSError as err:
        sock.close()
        raise BusError(
            f"cannot send multicast from {addressing.interface} ({err.strerror}); {FIX_HINT}"
        ) from None
    return sock


def open_receiver(addressing: Addressing, channel: int) -> socket.socket:
    """Open a non-blocking socket that receives one channel's group of the domain."""
    group = addressing.group(channel)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RCVBUF_WANTED)
        # bound to the group itself: with SO_REUSEPORT, a socket bound to 0.0.0.0 can be
        # handed another group's datagrams arriving on a real interface (reuseport picks one
        # socket per flow); the group address makes the kernel filter by destination
        sock.bind((group, addressing.port))
        membership = struct.pack(
            "4s4s", socket.inet_aton(group), socket.inet_aton(addressing.interface)
        )
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
    except OSError as err:
        sock.close()
        raise BusError(
            f"cannot join multicast group {group} on {addressing.interface} port "
            f"{addressing.port} ({err.strerror}); {FIX_HINT}"
        ) from None
    sock.setblocking(False)
    _check_rcvbuf(sock)
    return sock


def backlog_from_env() -> int:
    """How long (ns) messages may wait in a socket for a queue: ``ROSL_BACKLOG_MS`` or default.

    Raises:
        BusError: ``ROSL_BACKLOG_MS`` is not a number of milliseconds from 0.
    """
    return int(env_number("ROSL_BACKLOG_MS", BACKLOG_MS, "milliseconds") * 1_000_000)


def _check_rcvbuf(sock: socket.socket) -> None:
    global _warned_rcvbuf
    granted = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 2  # linux reports double
    if granted < RCVBUF_WARN_BELOW and not _warned_rcvbuf:
        _warned_rcvbuf = True
        print(
            f"rosl: warning: the OS allows only {granted // 1024} KiB of receive buffer "
            f"(wanted {RCVBUF_WANTED // 1024 // 1024} MiB); fast or large topics may lose "
            f"messages. Raise it: sudo sysctl -w net.core.rmem_max={RCVBUF_WANTED}",
            file=sys.stderr,
        )


class MulticastTransport:
    """UDP multicast on one domain: one sending socket, receivers with sockets of their own."""

    def __init__(self, addressing: Addressing, auth: Auth | Literal["env"] | None = "env") -> None:
        """Open the sending socket.

        Args:
            addressing: the domain's groups and port, and the interface.
            auth: the key datagrams are signed and checked with; ``"env"``: as the
                environment says (:func:`rosl.bus.auth.load`); None: no authentication.
        """
        self.addressing = addressing
        self.auth = keys.load(addressing.domain) if auth == "env" else auth
        # large messages between processes of this host (None: ROSL_SHM=0 or no /dev/shm)
        self.shm = shared.SharedMemory(addressing.domain) if shared.enabled() else None
        self.name = "multicast"
        self.fix_hint = FIX_HINT
        self.domain = addressing.domain
        self.max_datagram = addressing.max_datagram
        self.pacer = pacer_from_env(addressing.interface == LOOPBACK)
        self._sender = open_sender(addressing)
        self._targets = [(addressing.group(c), addressing.port) for c in range(CHANNELS + 1)]
        self._receivers: list[MulticastReceiver] = []
        self._raw: dict[int, socket.socket] = {}
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
            self._failed(err, target)

    def datagram_sender(self, channel: int) -> Callable[[Buffer], None]:
        """:meth:`send` of one whole datagram on ``channel``, its lookups done once (a writer's)."""
        target = self._targets[channel]
        sendto = self._sender.sendto

        def send_one(data: Buffer) -> None:
            try:
                sendto(data, target)
            except (BlockingIOError, InterruptedError):
                self.send_errors += 1
            except OSError as err:
                self._failed(err, target)

        return send_one

    def _failed(self, err: OSError, target: tuple[str, int]) -> None:
        """A send failed for another reason than a full buffer: an error, unless shut down."""
        if self._sender.fileno() < 0:
            return  # closed during shutdown
        raise BusError(
            f"cannot send to {target[0]}:{target[1]} ({err.strerror}); {FIX_HINT}"
        ) from None

    def receiver(self) -> MulticastReceiver:
        """A new receiver (its sockets are opened as it joins channels)."""
        receiver = MulticastReceiver(self.addressing, self.auth)
        if self.shm is not None:
            receiver.reader.shm = self.shm.reader()
        with self._lock:
            self._receivers.append(receiver)
        return receiver

    def open(self, channel: int) -> socket.socket:
        """The transport's own raw socket of a channel, opened once (tools read datagrams)."""
        with self._lock:
            sock = self._raw.get(channel)
            if sock is None:
                sock = self._raw[channel] = open_receiver(self.addressing, channel)
            return sock

    def describe(self) -> str:
        """The discovery group and port, and the interface they use."""
        where = self.addressing
        return f"{where.group(0)}:{where.port} via {where.interface}"

    def close(self) -> None:
        """Close every receiver and the sender (idempotent)."""
        with self._lock:
            receivers, self._receivers = self._receivers, []
            raw, self._raw = list(self._raw.values()), {}
        for receiver in receivers:
            receiver.close()
        for sock in raw:
            sock.close()
        self._sender.close()
        if self.shm is not None:
            self.shm.close()


class MulticastReceiver:
    """Channel sockets read with ``select``, woken through a pipe.

    Each socket has a kernel filter (:mod:`rosl.bus.kernel_filter`) letting in only the topics
    its reader wants: a busy topic sharing the channel of a quiet one wakes nobody else.
    """

    def __init__(self, addressing: Addressing, auth: Auth | None = None) -> None:
        self.addressing = addressing
        self.reader = Reader(auth)
        self._sockets: dict[int, socket.socket] = {}
        self._lock = threading.Lock()
        self.backlog_ns = backlog_from_env()  # (a bad setting raises before the pipe exists)
        self._wake_read, self._wake_write = os.pipe()
        os.set_blocking(self._wake_read, False)
        os.set_blocking(self._wake_write, False)
        self._closed = False
        self._caught_up: dict[int, int] = {}  # socket fd -> when stale messages were skipped
        # what a poll of every channel watches, rebuilt when a channel opens or closes (not
        # per poll: a 1 kHz timer polls a thousand times a second)
        self._watched: list[socket.socket | int] = [self._wake_read]
        self._channels: dict[int, int] = {}  # id(socket) -> channel
        # the reader's (want_all, wanted) the sockets' kernel filters were made from, and per
        # channel the hashes its filter lets in (None: no filter)
        self._filtered_from: tuple[bool, frozenset[int]] = (True, frozenset())
        self._filters: dict[int, frozenset[int] | None] = {}

    def _rewatch(self) -> None:
        """Rebuild the every-channel watch list (under ``_lock``)."""
        self._watched = [*self._sockets.values(), self._wake_read]
        self._channels = {id(sock): number for number, sock in self._sockets.items()}

    def join(self, channel: int) -> None:
        """Open the channel's socket (joining its group) unless it is open; update its filter."""
        with self._lock:
            if self._closed:
                return
            if channel not in self._sockets:
                self._sockets[channel] = open_receiver(self.addressing, channel)
                self._rewatch()
            self._refilter()

    def _refilter(self) -> None:
        """Make each socket's kernel filter let in the topics the reader wants (under ``_lock``).

        With ``want_all`` (recorders, monitors) nothing is filtered, nor is channel 0
        (discovery only).
        """
        reader = self.reader
        want_all, wanted = reader.want_all, frozenset(reader.wanted)
        self._filtered_from = (want_all, wanted)
        for channel, sock in self._sockets.items():
            hashes = (
                None
                if want_all or channel == 0
                else frozenset(h for h in wanted if channel_of(h) == channel)
            )
            if channel in self._filters and self._filters[channel] == hashes:
                continue
            if hashes is None:
                kernel_filter.detach(sock)
            elif not kernel_filter.attach(sock, hashes):
                hashes = None
            self._filters[channel] = hashes

    def leave(self, channel: int) -> None:
        """Close the channel's socket (leaving its group)."""
        with self._lock:
            sock = self._sockets.pop(channel, None)
            self._filters.pop(channel, None)
            if sock is not None:
                self._caught_up.pop(sock.fileno(), None)
                self._rewatch()
        if sock is not None:
            sock.close()

    def poll(
        self,
        timeout: float | None,
        out: list[Delivery],
        channel: int | None = None,
        limits: Mapping[int, int] | None = None,
    ) -> int:
        """Wait for datagrams (or a wake-up) and append the complete messages to ``out``.

        ``limits`` bounds what is read per channel (see :meth:`_drain`).
        """
        with self._lock:
            if self._closed:
                return 0
            reader, (want_all, wanted) = self.reader, self._filtered_from
            if reader.want_all is not want_all or reader.wanted != wanted:
                self._refilter()  # the reader's topics changed since the filters were made
            if channel is None:
                watched = self._watched  # replaced, never changed in place
            else:
                sock = self._sockets.get(channel)
                watched = [] if sock is None else [sock]
            channels = self._channels
        if not watched:
            return 0
        try:
            ready, _, _ = select.select(
                watched, [], [], None if timeout is None else max(0.0, timeout)
            )
        except (OSError, ValueError):
            return 0  # a socket closed under us (shutdown)
        drained = 0
        for item in ready:
            if isinstance(item, socket.socket):
                drained += 1
                limit = None if limits is None else limits.get(channels.get(id(item), -1))
                self._drain(item, out, limit)
            else:
                with contextlib.suppress(OSError):
                    while os.read(self._wake_read, 4096):
                        pass
        return drained

    def _drain(self, sock: socket.socket, out: list[Delivery], limit: int | None) -> None:
        """Read one socket's datagrams: up to ``limit``, unless those waiting are stale.

        Always bounded (:data:`DRAIN_LIMIT`): a sender faster than we parse must not grow
        ``out`` without end; what is left stays in the socket for the next poll. With a
        ``limit`` (the depth of the queues the channel's messages go to), no more is read
        than they hold: the kernel's receive buffer, megabytes deep, absorbs a burst of many
        publishers that a 10-deep queue would lose. But when the last message read waited in
        the socket longer than :data:`BACKLOG_MS` (``ROSL_BACKLOG_MS``), the rest is read at
        once and keep-last queues keep the newest: a callback slower than its publishers
        gets fresh messages, not ones that waited seconds in the kernel. At most once per
        bound per socket: a process that cannot keep up at all must not spend its time
        reading messages only to push them out of a queue again.
        """
        if limit is None or limit >= DRAIN_LIMIT:
            self.reader.drain(sock.recv, out, DRAIN_LIMIT)
            return
        start = len(out)
        if self.reader.drain(sock.recv, out, max(1, limit)) and len(out) > start:
            last = out[-1]
            stale = last.received - last.stamp > self.backlog_ns  # (the sender's stamp)
            key = sock.fileno()
            if stale and last.received - self._caught_up.get(key, 0) > self.backlog_ns:
                self._caught_up[key] = last.received
                self.reader.drain(sock.recv, out, DRAIN_LIMIT)

    def wake(self) -> None:
        """Wake a thread blocked in :meth:`poll`."""
        with contextlib.suppress(OSError):
            os.write(self._wake_write, b"x")

    def close(self) -> None:
        """Close every socket and the wake-up pipe (idempotent)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            sockets, self._sockets = list(self._sockets.values()), {}
            self._rewatch()
        if self.reader.shm is not None:
            self.reader.shm.release()  # writers stop waiting for this receiver's reads
        self.wake()
        for sock in sockets:
            sock.close()
        for fd in (self._wake_read, self._wake_write):
            with contextlib.suppress(OSError):
                os.close(fd)
