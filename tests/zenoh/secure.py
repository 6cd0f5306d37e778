"""Zenoh configuration files with authentication, made by a test in its own folder.

User/password (``transport/auth/usrpwd`` with a dictionary file) and TLS
(``transport/link/tls``: a CA and a certificate for the test's addresses, made with the
``openssl`` command line; tests that need it skip when it is not installed).
"""

from __future__ import annotations

import json
import shutil
import subprocess
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from pathlib import Path

USER, PASSWORD = "robot", "s3cret"


def _openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True, timeout=60)


def make_tls(folder: Path, addresses: list[str], name: str = "") -> dict[str, str]:
    """A CA and a certificate for ``addresses`` (IPs) and localhost; Zenoh's TLS settings."""
    if shutil.which("openssl") is None:
        pytest.skip("the TLS test needs the openssl command line")
    folder = folder / f"tls{name}"
    folder.mkdir()
    ec = ("-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:P-256", "-nodes")
    _openssl("req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "2",
             "-subj", "/CN=rosl test CA", cwd=folder)  # fmt: skip
    _openssl("req", *ec, "-keyout", "key.pem", "-out", "leaf.csr", "-subj", "/CN=localhost",
             cwd=folder)  # fmt: skip
    names = ",".join(["DNS:localhost", *(f"IP:{address}" for address in addresses)])
    (folder / "ext.cnf").write_text(
        f"subjectAltName={names}\nbasicConstraints=CA:FALSE\n"
        "extendedKeyUsage=serverAuth,clientAuth\n"
    )
    _openssl("x509", "-req", "-in", "leaf.csr", "-CA", "ca.pem", "-CAkey", "ca.key",
             "-CAcreateserial", "-out", "cert.pem", "-days", "2", "-extfile", "ext.cnf",
             cwd=folder)  # fmt: skip
    return {
        "root_ca_certificate": str(folder / "ca.pem"),
        "listen_private_key": str(folder / "key.pem"),
        "listen_certificate": str(folder / "cert.pem"),
    }


class Secured:
    """Configuration files for one router and its sessions, with user/password and/or TLS."""

    def __init__(
        self, folder: Path, router: str, tls: dict[str, str] | None = None, users: bool = True
    ) -> None:
        self.folder = folder
        self.router = router  # its endpoint, e.g. tcp/127.0.0.1:7447 (port 0: read it back)
        self.tls = tls
        self.users = folder / "users.txt" if users else None
        if self.users is not None:
            self.users.write_text(f"{USER}:{PASSWORD}\n")

    def _transport(self, password: str | None) -> dict[str, Any]:
        # as rmw_zenoh's files: zenoh's own shared memory off (a killed process would leave
        # its pool in /dev/shm)
        transport: dict[str, Any] = {"shared_memory": {"enabled": False}}
        if self.users is not None:
            auth: dict[str, str] = {"dictionary_file": str(self.users)}
            if password is not None:  # peers link to each other too: each checks the other
                auth |= {"user": USER, "password": password}
            transport["auth"] = {"usrpwd": auth}
        if self.tls is not None:
            transport["link"] = {"tls": self.tls}
        return transport

    def router_file(self) -> Path:
        """The router's configuration (ZENOH_ROUTER_CONFIG_URI)."""
        path = self.folder / "router.json5"
        path.write_text(json.dumps({
            "mode": "router", "listen": {"endpoints": [self.router]},
            "scouting": {"multicast": {"enabled": False}}, "transport": self._transport(None),
            "adminspace": {"enabled": True},  # it prints the port it was given
        }))  # fmt: skip
        return path

    def session_env(self, listen: str, password: str = PASSWORD) -> dict[str, str]:
        """The environment of a rosl process whose session uses ``password``."""
        path = self.folder / f"session-{password}-{listen.replace('/', '_')}.json5"
        path.write_text(json.dumps({
            "mode": "peer", "connect": {"endpoints": [self.router]},
            "listen": {"endpoints": [listen]}, "scouting": {"multicast": {"enabled": False}},
            "transport": self._transport(password),
        }))  # fmt: skip
        return {"ROSL_TRANSPORT": "zenoh", "ZENOH_SESSION_CONFIG_URI": str(path),
                "ZENOH_CONFIG_OVERRIDE": ""}  # fmt: skip


# a rosl process that reports whether its session linked to a router
LINKED = (
    "import time; from rosl.bus.zenoh_transport import ZenohTransport; "
    "t = ZenohTransport(0); deadline = time.monotonic() + 20\n"
    "while not t.session.info.routers_zid() and time.monotonic() < deadline:\n"
    "    time.sleep(0.05)\n"
    "print('linked' if t.session.info.routers_zid() else 'alone'); t.close()"
)
