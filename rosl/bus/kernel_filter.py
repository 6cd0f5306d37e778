"""Socket filters: the kernel drops datagrams of topics nobody in this process listens to.

Many topics share one multicast channel (a group), so a process that joined a channel for one
small topic also gets every datagram of the busy topics hashed to the same channel, and pays a
wake-up and a header parse for each. A classic BPF program attached to the channel's socket
(``SO_ATTACH_FILTER``) compares the topic hash in the datagram header with the hashes wanted
on that channel and lets only those through, before they are queued or wake anyone.

The program fails open: anything that does not start with rosl's magic is let through (the
reader counts it as foreign), as is everything when the wanted set is too large for one
program, and a kernel that refuses filters (not Linux) simply gets no filter. The
:class:`~rosl.bus.wire.Reader` keeps filtering by topic in any case.

Hand-written: a filter is a few instructions; no maintained Python package builds classic BPF
socket filters without a compiler toolchain (bcc, libbpf).
"""

from __future__ import annotations

import ctypes
import socket
import struct
import sys
from typing import TYPE_CHECKING

from rosl.bus.header import HEADER_SIZE, MAGIC

if TYPE_CHECKING:
    from collections.abc import Collection

__all__ = ["MAX_HASHES", "attach", "detach", "most_hashes", "program"]

SO_ATTACH_FILTER = 26  # linux/asm-generic/socket.h (not exported by the socket module)
SO_DETACH_FILTER = 27
UDP_HEADER = 8  # a UDP socket's filter sees the UDP header first, then the payload
TOPIC_OFFSET = 20  # where the topic hash starts in rosl's header (see header.py)
MAX_HASHES = 600  # 5 instructions each; the kernel takes programs up to 4096 instructions
HASH_COST = 260  # bytes of socket option memory (net.core.optmem_max) a filter takes per hash

_INSTRUCTION = struct.Struct("HBBI")  # struct sock_filter: code, jt, jf, k
_LD_H = 0x28  # BPF_LD | BPF_H | BPF_ABS: A = 16-bit word at k (network order)
_LD_W = 0x20  # BPF_LD | BPF_W | BPF_ABS: A = 32-bit word at k (network order)
_LD_LEN = 0x80  # BPF_LD | BPF_W | BPF_LEN: A = the datagram's length (UDP header included)
_JEQ = 0x15  # BPF_JMP | BPF_JEQ | BPF_K: pc += (A == k) ? jt : jf
_JGE = 0x35  # BPF_JMP | BPF_JGE | BPF_K: pc += (A >= k) ? jt : jf
_RET = 0x06  # BPF_RET | BPF_K: keep k bytes (0: drop)
_KEEP = 0xFFFFFFFF
_DROP = 0


def program(hashes: Collection[int]) -> list[tuple[int, int, int, int]]:
    """The filter keeping rosl datagrams whose topic is one of ``hashes`` (and foreign ones)."""
    at = UDP_HEADER + TOPIC_OFFSET
    code = [
        (_LD_LEN, 0, 0, 0),
        (_JGE, 0, 2, UDP_HEADER + HEADER_SIZE),
        (_LD_H, 0, 0, UDP_HEADER),
        (_JEQ, 1, 0, int.from_bytes(MAGIC, "big")),
        (_RET, 0, 0, _KEEP),  # too short, or not rosl's: the reader counts it as foreign
    ]
    for value in sorted(hashes):
        raw = value.to_bytes(8, "little")  # the header is little endian; loads are big endian
        code += [
            (_LD_W, 0, 0, at),
            (_JEQ, 0, 3, int.from_bytes(raw[:4], "big")),
            (_LD_W, 0, 0, at + 4),
            (_JEQ, 0, 1, int.from_bytes(raw[4:], "big")),
            (_RET, 0, 0, _KEEP),
        ]
    code.append((_RET, 0, 0, _DROP))
    return code


def most_hashes() -> int:
    """How many hashes one filter may hold here.

    :data:`MAX_HASHES`, or fewer where the kernel's socket option memory
    (``net.core.optmem_max``, 20 KiB before Linux 6.9) is small.
    """
    try:
        with open("/proc/sys/net/core/optmem_max", encoding="ascii") as handle:
            budget = int(handle.read().strip())
    except (OSError, ValueError):
        return MAX_HASHES
    return max(0, min(MAX_HASHES, budget * 2 // 5 // HASH_COST))  # leaves room for the rest


def attach(sock: socket.socket, hashes: Collection[int]) -> bool:
    """Let only ``hashes`` (and foreign datagrams) into ``sock``; False: no filter at all.

    More hashes than :func:`most_hashes`, or a kernel that refuses the program: the socket
    is left with no filter (everything comes in), never with an older one.
    """
    if not sys.platform.startswith("linux"):
        return False
    if len(hashes) > _MOST:
        detach(sock)
        return False
    code = program(hashes)
    instructions = ctypes.create_string_buffer(b"".join(_INSTRUCTION.pack(*i) for i in code))
    # struct sock_fprog on 64-bit Linux (elsewhere the kernel refuses it: no filter)
    fprog = struct.pack("HxxxxxxQ", len(code), ctypes.addressof(instructions))
    for _ in range(2):  # the kernel copies the program: the buffer may go once this returns
        try:
            sock.setsockopt(socket.SOL_SOCKET, SO_ATTACH_FILTER, fprog)
        except OSError:
            detach(sock)  # replacing charges the old program and the new one at once: again
            continue
        return True
    return False


def detach(sock: socket.socket) -> bool:
    """Take the filter off (everything comes in); False if there was none or the OS refuses."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        sock.setsockopt(socket.SOL_SOCKET, SO_DETACH_FILTER, 0)
    except OSError:
        return False
    return True


_MOST = most_hashes()
