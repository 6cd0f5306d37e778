"""Zenoh configuration as rmw_zenoh users set it: a router on localhost:7447, peers, env overrides.

* a session (every rosl process on the Zenoh transport) is a peer that connects to the router
  at ``tcp/localhost:7447`` and listens on a free port of localhost, with multicast scouting
  off and Zenoh's shared memory off, as rmw_zenoh's default session configuration;
  ``ZENOH_SESSION_CONFIG_URI`` names a Zenoh configuration file to start from instead;
* ``rosl zenoh router`` opens a session in router mode listening on ``tcp/127.0.0.1:7447``;
  ``ZENOH_ROUTER_CONFIG_URI`` names a file to start from instead;
* peers dial each other one way only (the greater Zenoh id dials) unless the file says
  otherwise: two peers dialling each other at once lose both links when they authenticate;
* ``ZENOH_CONFIG_OVERRIDE`` (``key=value;key=value``, each value JSON5) applies last to
  both, e.g. ``connect/endpoints=["tcp/192.168.1.2:7447"]``.
"""

from __future__ import annotations

import json
import os
import re
from typing import TYPE_CHECKING

from rosl.bus.errors import BusError

if TYPE_CHECKING:
    import zenoh

ROUTER_ENDPOINT = "tcp/localhost:7447"
ROUTER_LISTEN = "tcp/127.0.0.1:7447"
GOSSIP = "scouting/gossip"
ONE_DIAL = '{"peer": {"to_router": "always", "to_peer": "greater-zid"}}'


def _zenoh() -> object:
    try:
        import zenoh
    except ImportError as err:  # pragma: no cover - a dependency of rosl
        raise BusError(f"the Zenoh transport needs eclipse-zenoh: {err}") from None
    return zenoh


def _base(uri_variable: str, defaults: dict[str, str]) -> zenoh.Config:
    import zenoh

    _zenoh()
    path = os.environ.get(uri_variable, "").strip()
    if path:
        try:
            return zenoh.Config.from_file(path)
        except (zenoh.ZError, OSError, ValueError) as err:
            raise BusError(f"{uri_variable}={path}: not a Zenoh configuration: {err}") from None
    config = zenoh.Config()
    for key, value in defaults.items():
        _insert(config, key, value, key)
    return config


def _insert(config: zenoh.Config, key: str, value: str, what: str) -> None:
    """Set one configuration value (JSON5); BusError naming ``what`` when Zenoh refuses it."""
    import zenoh

    try:
        config.insert_json5(key, value)
    except (zenoh.ZError, ValueError) as err:
        raise BusError(f"{what}: Zenoh refuses {value}: {_reason(err)}") from None


def _reason(err: Exception) -> str:
    """The first line of a Zenoh error, without its source location."""
    text = str(err).split(" at /", 1)[0].replace("\\n", "\n").strip()
    line = text.splitlines()[0].strip() if text else type(err).__name__
    quoted = re.search(r'msg: "([^"]*)', line)  # Rust's debug form: Json5Err(Message { msg: "...
    return quoted.group(1) if quoted else line


def apply_overrides(config: zenoh.Config, overrides: str | None = None) -> zenoh.Config:
    """Apply ``ZENOH_CONFIG_OVERRIDE`` (or ``overrides``) to a configuration.

    Raises:
        BusError: an override that is not ``key=value`` or that Zenoh refuses.
    """
    text = os.environ.get("ZENOH_CONFIG_OVERRIDE", "") if overrides is None else overrides
    for item in filter(None, (part.strip() for part in text.split(";"))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise BusError(f"ZENOH_CONFIG_OVERRIDE: {item!r} is not key=value")
        _insert(config, key.strip(), value.strip(), f"ZENOH_CONFIG_OVERRIDE: {item!r}")
    return config


def session_config() -> zenoh.Config:
    """A peer's configuration: rmw_zenoh's defaults, the file, then the overrides."""
    defaults = {
        "mode": '"peer"',
        "connect/endpoints": f'["{ROUTER_ENDPOINT}"]',
        "listen/endpoints": '["tcp/localhost:0"]',
        "scouting/multicast/enabled": "false",
        # rmw_zenoh's default too; zenoh's own would map a shared-memory pool in /dev/shm that
        # a killed process leaves behind (rosl's own rings carry large messages on one host)
        "transport/shared_memory/enabled": "false",
    }
    config = _base("ZENOH_SESSION_CONFIG_URI", defaults)
    if config.get_json(f"{GOSSIP}/autoconnect_strategy") in ("null", ""):
        # one dial per pair of peers: when both dial at once, authenticated links (user and
        # password) are refused on both sides and never retried, and the router does not
        # carry what the two peers say to each other
        _insert(config, f"{GOSSIP}/autoconnect_strategy", ONE_DIAL, "autoconnect_strategy")
    return apply_overrides(config)


def router_config(listen: str | None = None) -> zenoh.Config:
    """A router's configuration: listening on ``listen`` (localhost:7447), no scouting."""
    defaults = {
        "mode": '"router"',
        "listen/endpoints": json.dumps([ROUTER_LISTEN]),
        "scouting/multicast/enabled": "false",
        "transport/shared_memory/enabled": "false",
    }
    config = apply_overrides(_base("ZENOH_ROUTER_CONFIG_URI", defaults))
    if listen:  # the command line wins over the file and the overrides
        _insert(config, "listen/endpoints", json.dumps([listen]), "--listen")
        if listen.endswith(":0"):  # a port the system picks: read back from the admin space
            _insert(config, "adminspace/enabled", "true", "--listen")
    return config


def listening_on(session: zenoh.Session, timeout: float = 2.0) -> str:
    """Where a router listens, as its admin space says ("" at once when it is not enabled)."""
    import zenoh

    try:
        for reply in session.get(f"@/{session.info.zid()}/router", timeout=timeout):
            if reply.ok is not None:
                locators = json.loads(reply.ok.payload.to_string()).get("locators") or []
                return ", ".join(str(locator) for locator in locators)
    except (zenoh.ZError, ValueError, AttributeError):
        pass
    return ""


def check_auth(config: zenoh.Config) -> None:
    """Refuse half a user/password pair, which Zenoh ignores (it links without it).

    Raises:
        BusError: ``transport/auth/usrpwd`` has a user and no password, or the reverse.
    """
    given = {
        field: config.get_json(f"transport/auth/usrpwd/{field}") not in ("null", '""', "")
        for field in ("user", "password")
    }
    if given["user"] != given["password"]:
        have, lack = ("user", "password") if given["user"] else ("password", "user")
        raise BusError(
            f"transport/auth/usrpwd has a {have} but no {lack} (Zenoh ignores half a pair: "
            "set both, in the configuration file or ZENOH_CONFIG_OVERRIDE)"
        )


def open_session(config: zenoh.Config) -> zenoh.Session:
    """Open a Zenoh session; BusError naming the endpoints when Zenoh cannot."""
    import zenoh

    check_auth(config)
    try:
        return zenoh.open(config)
    except zenoh.ZError as err:
        where = ", ".join(
            f"{key} {config.get_json(key)}"
            for key in ("listen/endpoints", "connect/endpoints")
            if config.get_json(key) not in ("[]", "null", "")
        )
        detail = f" ({where})" if where else ""
        raise BusError(f"cannot open a Zenoh session{detail}: {_reason(err)}") from None


def serve_forever(session: zenoh.Session) -> None:
    """Keep a (router) session open until interrupted, then close it."""
    import threading

    try:
        threading.Event().wait()
    finally:
        session.close()  # type: ignore[no-untyped-call]


def router_listen_text() -> str:
    """Where a router without ``--listen`` listens, for messages."""
    path = os.environ.get("ZENOH_ROUTER_CONFIG_URI", "").strip()
    return f"the endpoints of {path}" if path else ROUTER_LISTEN
