"""Datagram authentication: the domain key, and the MAC every datagram carries.

Every datagram a keyed process sends ends with a 16-byte MAC over its header and payload
(:attr:`~rosl.bus.header.Flags.SIGNED` says the trailer is there). A keyed receiver drops,
and counts, every datagram without a MAC or with a wrong one before it reads anything else.
So processes that share a key hear each other and nobody else: another user's processes on
the same host, whose default key differs, are dropped unseen.

Where the key comes from (:func:`load`):

* ``ROSL_KEY=none``: no key. Nothing is signed and everything is accepted (signed datagrams
  too: their MAC is skipped); any local process can publish, call services, set parameters.
* ``ROSL_KEY=<text>``: that text is the secret (share it across users or hosts).
* ``ROSL_KEY_FILE=<path>``: the first line of that file is the secret (others than its owner
  and group must not be able to read it).
* otherwise the user's own secret in ``~/.rosl/key`` (``ROSL_HOME`` moves the folder),
  created on first use with 32 random bytes and mode 0600; a key file other users can read is
  refused, as ssh refuses such a private key.

A secret of 32 or more hex digits (128+ random bits, as made here) is used as it is; anything
else is a passphrase and goes through scrypt first (once per process, ~80 ms), so a captured
datagram does not let anyone guess it at hashing speed. One key per domain is derived from
it, so traffic of one domain never verifies in another. Two keyed hashes, picked by the
datagram's length so both sides agree without a field, both cut to 16 bytes: BLAKE2b
(``hashlib``) for datagrams up to :data:`SMALL` bytes, where a call costs least (0.7 us for
100 bytes, against 2.2 us for HMAC-SHA256), and BLAKE3 (the ``blake3`` package) above, four
times as fast as BLAKE2b and twice HMAC-SHA256 on a 64 KB fragment (3 GB/s). Hand-written
because it is a few calls into those libraries; no library frames UDP datagrams for us.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import os
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from blake3 import blake3

from rosl.bus.errors import BusError

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping, Sequence

    from rosl.bus.transport import Buffer

MAC_SIZE = 16
_compare_digest = hmac.compare_digest  # (one lookup less per datagram)
SMALL = 2048  # header + payload up to this many bytes: keyed BLAKE2b; above: keyed BLAKE3
KEY_FILE = "key"
OFF = "none"


class Auth:
    """Signs and verifies datagrams under one domain's key."""

    def __init__(self, secret: bytes, domain: int, source: str) -> None:
        if not _random_enough(secret):
            secret = hashlib.scrypt(secret, salt=b"rosl passphrase", n=1 << 14, r=8, p=1)
        master = hashlib.blake2b(secret, digest_size=32, person=b"rosl-key").digest()
        salt = domain.to_bytes(4, "little")
        small_key = hashlib.blake2b(salt + b"blake2b", key=master).digest()
        self._small = hashlib.blake2b(key=small_key, digest_size=MAC_SIZE)  # copied per use
        self._large = blake3(
            key=hashlib.blake2b(salt + b"blake3", key=master, digest_size=32).digest()
        )
        self.source = source  # where the key came from, for rosl doctor
        self.fingerprint = hashlib.blake2b(master, digest_size=4).hexdigest()

    def mac(self, body: Buffer) -> bytes:
        """The MAC of one datagram's header and payload (contiguous)."""
        return self.mac_parts((body,))

    def mac_parts(self, parts: Sequence[Buffer]) -> bytes:
        """The MAC of a datagram given as parts (scatter send: nothing is joined)."""
        if sum(map(len, parts)) <= SMALL:
            small = self._small.copy()  # cheaper than keying anew
            for part in parts:
                small.update(part)
            return small.digest()
        large = self._large.copy()
        for part in parts:
            large.update(part)
        return large.digest(MAC_SIZE)

    def signed(self, body: bytes) -> bytes:
        """A small datagram's header and payload with its MAC appended (one call per send)."""
        if len(body) > SMALL:
            return body + self.mac(body)
        small = self._small.copy()
        small.update(body)
        return body + small.digest()

    def small_signer(self) -> Callable[[bytes], bytes]:
        """:meth:`signed` for datagrams of at most :data:`SMALL` bytes (the caller knows)."""
        copy = self._small.copy

        def sign(body: bytes) -> bytes:
            small = copy()
            small.update(body)
            return body + small.digest()

        return sign

    def verify(self, datagram: bytes) -> bool:
        """Whether a datagram's trailing MAC is right for the rest of it."""
        end = len(datagram) - MAC_SIZE
        if 0 <= end <= SMALL:  # the common case (per datagram), with no call in between
            small = self._small.copy()
            small.update(datagram[:end])  # (a copy of up to 2 KiB costs less than a view)
            return _compare_digest(small.digest(), datagram[end:])
        if end < 0:
            return False
        return _compare_digest(self.mac(memoryview(datagram)[:end]), datagram[end:])


def home() -> Path:
    """The user's rosl folder (``ROSL_HOME``, else ``~/.rosl``)."""
    configured = os.environ.get("ROSL_HOME", "").strip()
    return Path(configured).expanduser() if configured else Path.home() / ".rosl"


def load(domain: int, env: Mapping[str, str] | None = None) -> Auth | None:
    """The domain's key as the environment says (None: authentication is off).

    Raises:
        BusError: a key file that cannot be read, is empty, or other users can read.
    """
    environ = os.environ if env is None else env
    value = environ.get("ROSL_KEY", "")
    if value.strip().lower() == OFF:
        return None
    if value:
        return Auth(value.encode(), domain, "ROSL_KEY")
    named = environ.get("ROSL_KEY_FILE", "").strip()
    if named:
        path = Path(named).expanduser()
        return Auth(_read(path, group=True), domain, f"ROSL_KEY_FILE={path}")
    path = home() / KEY_FILE
    return Auth(_own_secret(path), domain, str(path))


def _random_enough(secret: bytes) -> bool:
    """Whether a secret is 32+ hex digits (a made key), not a passphrase."""
    try:
        return len(secret) >= 32 and len(bytes.fromhex(secret.decode("ascii"))) >= 16
    except (UnicodeDecodeError, ValueError):
        return False


def _read(path: Path, group: bool) -> bytes:
    """A key file's first line; refused if others (or, unless ``group``, its group) can read it."""
    try:
        with path.open("rb") as handle:
            mode = os.fstat(handle.fileno()).st_mode
            text = handle.readline().strip()
    except OSError as err:
        raise BusError(f"cannot read the key file {path}: {err.strerror}") from None
    if mode & (stat.S_IRWXO if group else stat.S_IRWXG | stat.S_IRWXO):
        fix = "chmod 640" if group else "chmod 600"
        raise BusError(
            f"the key file {path} can be read by other users (mode {stat.S_IMODE(mode):04o}); "
            f"make it private: {fix} {path}"
        )
    if not text:
        raise BusError(f"the key file {path} is empty: delete it to get a new key")
    return text


def _own_secret(path: Path) -> bytes:
    """Read the user's key, creating it (mode 0600) on first use; safe when racing."""
    if not path.exists():
        import secrets  # once per user: not at every start

        try:
            path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
            draft = path.with_name(f".{KEY_FILE}.{os.getpid()}.{secrets.token_hex(4)}")
            fd = os.open(draft, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, "w") as handle:
                handle.write(secrets.token_hex(32) + "\n")
            try:
                os.link(draft, path)  # atomic: of two first processes, one key wins
            except FileExistsError:
                pass
            finally:
                with contextlib.suppress(OSError):
                    draft.unlink()
        except OSError as err:
            raise BusError(
                f"cannot create the key file {path}: {err.strerror} (set ROSL_HOME to a "
                "writable folder, or ROSL_KEY / ROSL_KEY_FILE to a shared key)"
            ) from None
    return _read(path, group=False)
