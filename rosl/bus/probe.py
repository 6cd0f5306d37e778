"""ROS 2's multicast check (``ros2 multicast send/receive``): one UDP datagram to a group.

Unlike the bus, the check does not depend on the domain: ROS 2 uses group 225.0.0.1 and port
49150, and so does this module, so a ``rosl`` and a ``ros2`` on the same interface hear each
other. As everywhere in rosl the datagram stays on this host by default (sent out of 127.0.0.1
with TTL 0, joined on 127.0.0.1); ``ROSL_INTERFACE`` names the interface to check instead,
where the TTL becomes 1 (or what ``--ttl`` says).
"""

from __future__ import annotations

import ipaddress
import os
import select
import socket
import struct
import time
from dataclasses import dataclass

from rosl.bus.errors import BusError
from rosl.bus.multicast import IP_MULTICAST_ALL, LOOPBACK, interface_address

DEFAULT_GROUP = "225.0.0.1"
DEFAULT_PORT = 49150
GREETING = b"Hello World!"
MAX_DATAGRAM = 65535


@dataclass(frozen=True, slots=True)
class Scope:
    """Where the check's datagram goes.

    Attributes:
        interface: the IPv4 address the datagram is sent from and the group joined on.
        ttl: how many hops the datagram may take (0: this host only).
    """

    interface: str = LOOPBACK
    ttl: int = 0


@dataclass(frozen=True, slots=True)
class Datagram:
    """One datagram heard, and who sent it."""

    data: bytes
    host: str
    port: int


def scope_from_env(ttl: int | None = None) -> Scope:
    """The scope from ``ROSL_INTERFACE`` (loopback when unset) and an explicit TTL.

    Raises:
        BusError: ``ROSL_INTERFACE`` names no interface with an IPv4 address, or a bad TTL.
    """
    if ttl is not None and not 0 <= ttl <= 255:
        raise BusError(f"--ttl {ttl}: a multicast TTL goes from 0 to 255")
    name = os.environ.get("ROSL_INTERFACE", "").strip()
    address = interface_address(name) if name else LOOPBACK
    if ttl is None:
        ttl = 0 if address.startswith("127.") else 1
    return Scope(address, ttl)


def check_group(group: str) -> str:
    """Return ``group`` if it is an IPv4 multicast address.

    Raises:
        BusError: it is not one.
    """
    try:
        address = ipaddress.IPv4Address(group)
    except ValueError:
        raise BusError(f"--group {group}: not an IPv4 address") from None
    if not address.is_multicast:
        raise BusError(f"--group {group}: not a multicast address (224.0.0.0 to 239.255.255.255)")
    return group


def send(
    data: bytes = GREETING,
    *,
    group: str = DEFAULT_GROUP,
    port: int = DEFAULT_PORT,
    scope: Scope | None = None,
) -> None:
    """Send one datagram to ``group:port`` out of the scope's interface.

    Raises:
        BusError: the socket refused the interface, the TTL or the datagram.
    """
    scope = scope or Scope()
    check_group(group)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    try:
        sock.setsockopt(
            socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton(scope.interface)
        )
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, scope.ttl)
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        sock.sendto(data, (group, port))
    except OSError as err:
        raise BusError(
            f"cannot send a multicast datagram to {group}:{port} from {scope.interface} "
            f"({err.strerror})"
        ) from None
    finally:
        sock.close()


class Listener:
    """A socket joined to ``group`` on the scope's interface, receiving on ``port``.

    The group is joined when the listener is made, so a datagram sent after that is heard.
    """

    def __init__(
        self, *, group: str = DEFAULT_GROUP, port: int = DEFAULT_PORT, scope: Scope | None = None
    ) -> None:
        self.group = check_group(group)
        self.port = port
        self.scope = scope or Scope()
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
            self._sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
            self._sock.bind((group, port))  # the group itself: only its datagrams arrive
            membership = struct.pack(
                "4s4s", socket.inet_aton(group), socket.inet_aton(self.scope.interface)
            )
            self._sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        except OSError as err:
            self._sock.close()
            raise BusError(
                f"cannot join multicast group {group} port {port} on {self.scope.interface} "
                f"({err.strerror})"
            ) from None
        self._sock.setblocking(False)

    def receive(self, timeout: float | None = None) -> Datagram:
        """Wait for one datagram; ``timeout`` None waits until interrupted.

        Raises:
            BusError: nothing arrived within ``timeout`` seconds.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            ready, _, _ = select.select([self._sock], [], [], 1.0 if left is None else left)
            if ready:
                try:
                    data, (host, port) = self._sock.recvfrom(MAX_DATAGRAM)
                except BlockingIOError:
                    continue
                return Datagram(data, host, port)
            if left is not None and left <= 0:
                raise BusError(
                    f"no UDP multicast datagram on {self.group}:{self.port} "
                    f"(joined on {self.scope.interface}) within {timeout:g} s"
                )

    def close(self) -> None:
        """Leave the group and close the socket."""
        self._sock.close()

    def __enter__(self) -> Listener:
        """Use the listener in a ``with`` block."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Close the listener."""
        self.close()
