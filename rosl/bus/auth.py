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
* ``ROSL_KEY_FILE=<path>``: the first line of that file is the secret.
* otherwise the user's own secret in ``~/.rosl/key`` (``ROSL_HOME`` moves the folder),
  created on first use with 32 random bytes and mode 0600; a key file other users can read is
  refused, as ssh refuses such a private key.

The secret is stretched into one key per domain, so traffic of one domain never verifies in
another. Two MACs, picked by the datagram's length so both sides agree without a field:
keyed BLAKE2b for datagrams up to :data:`SMALL` bytes (a third of HMAC's cost on a
100-byte datagram) and HMAC-SHA256 above (SHA extensions make it twice as fast as BLAKE2b on
a 64 KB fragment), both cut to 16 bytes. Hand-written because it is a few calls into
``hashlib`` and ``hmac``; no library frames UDP datagrams for us.
"""

from __future__ import annotations

import contextlib
import hashlib
import hmac
import os
import secrets
import stat
from pathlib import Path
from typing import TYPE_CHECKING

from rosl.bus.errors import BusError

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from rosl.bus.transport import Buffer

MAC_SIZE = 16
SMALL = 4096  # header + payload up to this many bytes: keyed BLAKE2b; above: HMAC-SHA256
KEY_FILE = "key"
OFF = "none"


class Auth:
    """Signs and verifies datagrams under one domain's key."""

    def __init__(self, secret: bytes, domain: int, source: str) -> None:
        master = hashlib.blake2b(secret, digest_size=32, person=b"rosl-key").digest()
        salt = domain.to_bytes(4, "little")
        self._small_key = hashlib.blake2b(salt + b"blake2b", key=master).digest()
        large_key = hashlib.blake2b(salt + b"hmac-sha256", key=master).digest()
        self._large = hmac.new(large_key, digestmod="sha256")
        self.source = source  # where the key came from, for rosl doctor
        self.fingerprint = hashlib.blake2b(master, digest_size=4).hexdigest()

    def mac(self, body: Buffer) -> bytes:
        """The MAC of one datagram's header and payload (contiguous)."""
        if len(body) <= SMALL:
            return hashlib.blake2b(body, key=self._small_key, digest_size=MAC_SIZE).digest()
        large = self._large.copy()
        large.update(body)
        return large.digest()[:MAC_SIZE]

    def mac_parts(self, parts: Sequence[Buffer]) -> bytes:
        """The MAC of a datagram given as parts (scatter send: nothing is joined)."""
        if sum(len(p) for p in parts) <= SMALL:
            small = hashlib.blake2b(key=self._small_key, digest_size=MAC_SIZE)
            for part in parts:
                small.update(part)
            return small.digest()
        large = self._large.copy()
        for part in parts:
            large.update(part)
        return large.digest()[:MAC_SIZE]

    def verify(self, datagram: bytes) -> bool:
        """Whether a datagram's trailing MAC is right for the rest of it."""
        end = len(datagram) - MAC_SIZE
        if end < 0:
            return False
        return hmac.compare_digest(self.mac(memoryview(datagram)[:end]), datagram[end:])


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
        return Auth(_read(path, private=False), domain, f"ROSL_KEY_FILE={path}")
    path = home() / KEY_FILE
    return Auth(_own_secret(path), domain, str(path))


def _read(path: Path, private: bool) -> bytes:
    try:
        with path.open("rb") as handle:
            mode = os.fstat(handle.fileno()).st_mode
            text = handle.readline().strip()
    except OSError as err:
        raise BusError(f"cannot read the key file {path}: {err.strerror}") from None
    if private and mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise BusError(
            f"the key file {path} can be read by other users (mode {stat.S_IMODE(mode):04o}); "
            f"make it private: chmod 600 {path}"
        )
    if not text:
        raise BusError(f"the key file {path} is empty: delete it to get a new key")
    return text


def _own_secret(path: Path) -> bytes:
    """Read the user's key, creating it (mode 0600) on first use; safe when racing."""
    if not path.exists():
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
    return _read(path, private=True)
