"""Which rosl process and endpoint a Zenoh sample's GID stands for.

rmw_zenoh's attachment names a publisher by its GID (a hash of its liveliness token), which
cannot be read back into rosl's (process, endpoint) pair. So every rosl session also declares
``@rosl_id/<domain>/<zid>/<process id>``; with the endpoint tokens of the same session
(``.../<zid>/<nid>/<eid>/...``), a GID maps back to the rosl process and endpoint that sent
it. Samples of rosl publishers then keep the ids the graph knows them by, as on the other
transports: the graph's QoS and lifespan apply, the lock-stepped simulator sees its
controllers' replies, loss is counted per publisher. Other implementations' GIDs stay as
they are (the transport derives ids from them).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from rosl.bus import zenoh_wire as wire

if TYPE_CHECKING:
    import zenoh

ID_SPACE = "@rosl_id"
MAX_ENTITIES = 65536  # GIDs remembered (strangers' tokens must not grow it without bound)


class Identities:
    """GID -> (rosl process, endpoint), learnt from liveliness tokens."""

    def __init__(self, session: zenoh.Session, domain: int, zid: str) -> None:
        self._session = session
        self._domain = domain
        self._zid = zid
        self._token: Any = None
        self._announced = 0
        self._lock = threading.Lock()
        self.owners: dict[bytes, tuple[int, int]] = {}  # read without the lock (hot path)
        self._senders: dict[str, int] = {}  # zid -> rosl process id
        self._entities: dict[bytes, tuple[str, int]] = {}  # gid -> (zid, endpoint)
        liveliness = session.liveliness()
        self._ids = liveliness.declare_subscriber(
            f"{ID_SPACE}/{domain}/*/*", self._on_id, history=True
        )
        self._tokens = liveliness.declare_subscriber(
            f"{wire.ADMIN_SPACE}/{domain}/**", self._on_token, history=True
        )

    def announce(self, sender: int) -> None:
        """This session's rosl process id (declared once per id)."""
        if sender == self._announced:
            return
        old, self._announced = self._token, sender
        self._token = self._session.liveliness().declare_token(
            f"{ID_SPACE}/{self._domain}/{self._zid}/{sender:016x}"
        )
        if old is not None:
            old.undeclare()

    def _on_id(self, sample: zenoh.Sample) -> None:
        import zenoh

        *_, zid, sender = str(sample.key_expr).split("/")
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                try:
                    self._senders[zid] = int(sender, 16)
                except ValueError:
                    return
            else:
                self._senders.pop(zid, None)
            self._rebuild()

    def _on_token(self, sample: zenoh.Sample) -> None:
        import zenoh

        key = str(sample.key_expr)
        try:
            entity = wire.parse_liveliness(key)
            endpoint = int(entity.eid) & 0xFFFF
        except ValueError:
            return
        if entity.kind == wire.NODE:
            return
        gid = wire.gid_of(key)
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                if len(self._entities) < MAX_ENTITIES:
                    self._entities[gid] = (entity.zid, endpoint)
            else:
                self._entities.pop(gid, None)
            self._rebuild()

    def _rebuild(self) -> None:
        """Recompute the map (under the lock); swapped in whole for lock-free readers."""
        self.owners = {
            gid: (self._senders[zid], endpoint)
            for gid, (zid, endpoint) in self._entities.items()
            if zid in self._senders
        }

    def close(self) -> None:
        """Stop following tokens; withdraw this session's id."""
        for handle in (self._ids, self._tokens, self._token):
            if handle is not None:
                handle.undeclare()
