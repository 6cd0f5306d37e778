"""``rosl doctor``: setup checks with one line each, ROS 2's summary line, and ``--report``.

Checks, in order: ``domain`` (the id and where it came from), ``network`` (our own graph query
comes back over multicast), ``security`` (whether datagrams are signed, with which key, and
what traffic of other keys or unsigned senders was dropped while listening), ``package``
(search path: broken package.xml fails, shadowing warns), ``interface`` (every .msg/.srv
parses and its references resolve), ``node`` (no two nodes share a name) and ``topic`` (one
type per topic; publishers without subscribers warn).
"""

from __future__ import annotations

import os
import platform
import socket
import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rosl.bus import multicast
from rosl.errors import RoslError
from rosl.graph.records import PUBLISHER, SUBSCRIPTION, is_hidden

if TYPE_CHECKING:
    from rosl.graph.cache import GraphCache
    from rosl.idl.search_path import SearchResult
    from rosl.introspection.session import Session

QUERY_TIMEOUT = 2.0
LISTEN_S = 1.2  # longer than a discovery period: every process announced itself once
QUIET_TOPICS = ("/parameter_events", "/rosout")  # never warned about, as in ros2doctor
MAX_DETAILS = 5


@dataclass(frozen=True, slots=True)
class CheckResult:
    """One check: its module name, whether it passed, a one-line summary, and the rest."""

    name: str
    passed: bool
    summary: str
    warnings: tuple[str, ...] = ()
    details: tuple[str, ...] = ()  # why it failed, one line each
    skipped: bool = False  # could not run because an earlier check failed (not a failure)


@dataclass(slots=True)
class Diagnosis:
    """Every check's result plus what was learnt on the way (for ``--report``)."""

    checks: list[CheckResult] = field(default_factory=list)
    domain: int | None = None
    addressing: multicast.Addressing | None = None
    domain_source: str = ""
    graph: GraphCache | None = None
    search: SearchResult | None = None

    @property
    def failed(self) -> list[CheckResult]:
        """The checks that failed."""
        return [c for c in self.checks if not c.passed]


def diagnose(session: Session, domain: int | None = None) -> Diagnosis:
    """Run every check (none raises: a broken step becomes a failed check)."""
    result = Diagnosis()
    for check in (_domain, _network, _security, _packages, _interfaces, _nodes, _topics):
        result.checks.append(check(result, session, domain))
    return result


# --- the checks -------------------------------------------------------------------------------


def _domain(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    del session
    ours, ros = (os.environ.get(n, "").strip() for n in ("ROSL_DOMAIN_ID", "ROS_DOMAIN_ID"))
    try:
        result.domain = multicast.domain_from_env(domain)
    except RoslError as err:
        return CheckResult("domain", False, str(err))
    result.domain_source = (
        "--domain-id"
        if domain is not None
        else "ROSL_DOMAIN_ID"
        if ours
        else "ROS_DOMAIN_ID"
        if ros
        else "default"
    )
    warnings = []
    if ours and ros and ours != ros:
        warnings.append(
            f"ROSL_DOMAIN_ID={ours} and ROS_DOMAIN_ID={ros} disagree; rosl uses "
            f"{'--domain-id' if domain is not None else 'ROSL_DOMAIN_ID'}"
        )
    summary = f"domain {result.domain} (from {result.domain_source})"
    return CheckResult("domain", True, summary, tuple(warnings))


def _network(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    if result.domain is None:
        return CheckResult("network", False, "not tried: no usable domain id")
    try:
        where = result.addressing = multicast.addressing_from_env(domain)
        discovery = session.participant.discovery
        complete = discovery.wait_complete(discovery.query(), timeout=QUERY_TIMEOUT)
    except RoslError as err:
        return CheckResult("network", False, str(err).splitlines()[0])
    result.graph = session.participant.graph
    processes = len(result.graph.processes())
    warnings = (
        ()
        if complete
        else (f"some processes did not answer the graph query within {QUERY_TIMEOUT} s",)
    )
    route = f"{where.group(0)}:{where.port} via {where.interface} (TTL {where.ttl})"
    summary = f"multicast works on {route}; {processes} process(es) answered"
    return CheckResult("network", True, summary, warnings)


def _security(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    """Authentication on or off, and what the discovery channel dropped while we listened."""
    del domain
    if result.graph is None:
        return CheckResult("security", True, "not checked: the bus is not usable", skipped=True)
    participant = session.participant
    auth = participant.transport.auth
    if auth is None:
        return CheckResult(
            "security",
            True,
            "authentication is off (ROSL_KEY=none)",
            ("any process on this host can publish, call services and set parameters",),
        )
    remaining = participant.discovery.started + LISTEN_S - time.monotonic()
    if remaining > 0:
        time.sleep(remaining)
    dropped = participant.discovery.dropped()
    strangers = dropped["forged"] + dropped["unsigned"]
    summary = f"datagrams are signed with the key from {auth.source} ({auth.fingerprint})"
    warnings: list[str] = []
    if strangers:
        warnings.append(
            f"dropped {strangers} datagram(s) of processes under another key or none "
            f"({dropped['forged']} with another key, {dropped['unsigned']} unsigned): another "
            "user's rosl, or ROSL_KEY differs; share a key with ROSL_KEY_FILE to hear them"
        )
    if dropped["stale"] or dropped["duplicates"]:
        warnings.append(
            f"dropped {dropped['stale']} stale and {dropped['duplicates']} repeated "
            "datagram(s): replayed traffic, or clocks more than 30 s apart"
        )
    return CheckResult("security", True, summary, tuple(warnings))


def _packages(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    from rosl.idl import search_path

    del session, domain
    search = result.search = search_path.scan()
    origins = Counter(p.origin for p in search.packages.values())
    where = ", ".join(f"{n} {o}" for o, n in sorted(origins.items()))
    summary = f"{len(search.packages)} packages on the search path ({where or 'none'})"
    warnings = tuple(
        f"package '{hidden.name}' in {hidden.path} is shadowed by {winner.path}"
        for hidden, winner in search.shadowed
    )
    details = tuple(err.render() for err in search.broken)
    if details:
        summary = f"{len(details)} broken package.xml; " + summary
    return CheckResult("package", not details, summary, warnings, _first(details))


def _interfaces(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError
    from rosl.idl.parser import ActionSpec, MessageSpec, ServiceSpec

    del session, domain
    checked, errors = 0, []
    for package in sorted(result.search.packages if result.search else ()):
        for kind in ("msg", "srv", "action"):
            for name in registry.list_types(package, kind):
                checked += 1
                try:
                    spec = registry.load_spec(f"{package}/{kind}/{name}")
                    halves: tuple[MessageSpec, ...]
                    if isinstance(spec, ActionSpec):
                        halves = spec.parts
                    elif isinstance(spec, ServiceSpec):
                        halves = (spec.request, spec.response)
                    else:
                        halves = (spec,)
                    for half in halves:
                        registry.resolve(half)
                except InterfaceError as err:
                    errors.append(err.render())
    if errors:
        summary = f"{len(errors)} of {checked} .msg/.srv/.action files have errors"
        return CheckResult("interface", False, summary, details=_first(tuple(errors)))
    return CheckResult("interface", True, f"{checked} .msg/.srv/.action files parse")


def _nodes(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    del session, domain
    if result.graph is None:
        return CheckResult(
            "node", True, "not checked: the graph could not be queried", skipped=True
        )
    names = Counter(n.fqn for n in result.graph.nodes())
    clashes = tuple(f"{count} nodes are named {name}" for name, count in names.items() if count > 1)
    if clashes:
        return CheckResult("node", False, "nodes with duplicate names", details=clashes)
    return CheckResult("node", True, f"{len(names)} nodes, every name unique")


def _incompatible_qos(graph: GraphCache, topic: str) -> list[str]:
    """A warning per publisher and subscription of one type that QoS keeps apart."""
    from rosl.node.qos_compatibility import mismatches

    subscriptions = graph.endpoints(SUBSCRIPTION, topic)
    found = []
    for pub_node, publisher in graph.endpoints(PUBLISHER, topic):
        for sub_node, subscription in subscriptions:
            if publisher.type != subscription.type:
                continue
            kinds = [m.kind.name for m in mismatches(publisher.qos, subscription.qos)]
            if kinds:
                found.append(
                    f"Incompatible QoS on {topic}: {sub_node.fqn} hears nothing from "
                    f"{pub_node.fqn} ({', '.join(kinds)})."
                )
    return found


def _topics(result: Diagnosis, session: Session, domain: int | None) -> CheckResult:
    del session, domain
    graph = result.graph
    if graph is None:
        return CheckResult(
            "topic", True, "not checked: the graph could not be queried", skipped=True
        )
    topics = graph.topics()
    mixed = tuple(
        f"topic {name} has more than one type: {', '.join(types)}"
        for name, types in topics.items()
        if len(types) > 1
    ) + _definition_clashes(graph)
    warnings = []
    for name in topics:
        if name in QUIET_TOPICS or is_hidden(name):
            continue
        publishers, subscribers = graph.count(PUBLISHER, name), graph.count(SUBSCRIPTION, name)
        if publishers and not subscribers:
            warnings.append(f"Publisher without subscriber detected on {name}.")
        elif subscribers and not publishers:
            warnings.append(f"Subscriber without publisher detected on {name}.")
        warnings += _incompatible_qos(graph, name)
    if mixed:
        return CheckResult("topic", False, "topic type mismatch", tuple(warnings), mixed)
    return CheckResult("topic", True, f"{len(topics)} topics, one type each", tuple(warnings))


def _definition_clashes(graph: GraphCache) -> tuple[str, ...]:
    """Topics whose endpoints read one type name from different .msg files."""
    digests: dict[tuple[str, str], dict[str, list[str]]] = {}
    for kind in (PUBLISHER, SUBSCRIPTION):
        for node, endpoint in graph.endpoints(kind):
            if endpoint.digest:
                by_digest = digests.setdefault((endpoint.name, endpoint.type), {})
                by_digest.setdefault(endpoint.digest, []).append(node.fqn)
    return tuple(
        f"topic {name}: {type_name} has {len(found)} different definitions "
        f"({'; '.join(', '.join(sorted(set(nodes))) for nodes in found.values())})"
        for (name, type_name), found in sorted(digests.items())
        if len(found) > 1
    )


def _first(lines: tuple[str, ...]) -> tuple[str, ...]:
    if len(lines) <= MAX_DETAILS:
        return lines
    return (*lines[:MAX_DETAILS], f"... and {len(lines) - MAX_DETAILS} more")


# --- rendering --------------------------------------------------------------------------------


def check_lines(diagnosis: Diagnosis) -> list[str]:
    """One line per check (warnings and reasons indented below), then ROS 2's summary."""
    lines = []
    for check in diagnosis.checks:
        status = (
            "FAIL"
            if not check.passed
            else "SKIP"
            if check.skipped
            else "WARN"
            if check.warnings
            else " OK "
        )
        lines.append(f"[{status}] {check.name}: {check.summary}")
        lines += [f"       {line}" for line in check.details]
        lines += [f"       UserWarning: {line}" for line in check.warnings]
    total, failed = len(diagnosis.checks), diagnosis.failed
    if not failed:
        return [*lines, "", f"All {total} checks passed", ""]
    names = " ".join(c.name for c in failed)
    return [*lines, "", f"{len(failed)}/{total} check(s) failed", "", f"Failed modules: {names}"]


def _section(title: str, items: list[tuple[str, str]]) -> list[str]:
    pad = max(8, *(len(name) + 4 for name, _ in items)) if items else 8
    return ["", f"   {title}", *(f"{name:{pad}}: {value}" for name, value in items)]


def report_lines(diagnosis: Diagnosis) -> list[str]:
    """ros2 doctor --report's sections, each line ``name<padded>: value``."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        rosl_version = version("rosl")
    except PackageNotFoundError:
        rosl_version = "unknown"
    where = diagnosis.addressing
    rosl_items = [
        ("version", rosl_version),
        ("python", sys.version.split()[0]),
        (
            "domain id",
            f"{diagnosis.domain} ({diagnosis.domain_source})"
            if diagnosis.domain is not None
            else "invalid",
        ),
        ("interface", os.environ.get("ROSL_INTERFACE", "").strip() or "loopback"),
    ]
    if diagnosis.search is not None:
        rosl_items += [(f"search path ({o})", str(p)) for p, o, _ in diagnosis.search.roots]
    lines = _section(
        "PLATFORM INFORMATION",
        [
            ("system", platform.system()),
            ("platform info", platform.platform()),
            ("release", platform.release()),
            ("processor", platform.machine()),
        ],
    )
    lines += _section("ROSL INFORMATION", rosl_items)
    if where is not None:
        lines += _section(
            "NETWORK CONFIGURATION",
            [
                ("hostname", socket.gethostname()),
                ("interface address", where.interface),
                ("multicast ttl", str(where.ttl)),
                ("port", str(where.port)),
                ("discovery group", where.group(0)),
                ("data groups", f"{where.group(1)} - {where.group(multicast.CHANNELS)}"),
                ("max datagram", f"{where.max_datagram} bytes"),
            ],
        )
    topics: list[tuple[str, str]] = []
    graph = diagnosis.graph
    for name in graph.topics() if graph is not None else {}:
        assert graph is not None
        topics += [
            ("topic", name),
            ("publisher count", str(graph.count(PUBLISHER, name))),
            ("subscriber count", str(graph.count(SUBSCRIPTION, name))),
        ]
    lines += _section("TOPIC LIST", topics or [("topic", "none")])
    return [*lines, ""]
