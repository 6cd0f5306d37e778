"""``service list/type/find/info/call``: the graph's services, and bounded calls.

``call`` waits for the service and for its answer with a default bound of a few seconds
(ros2 waits forever) and says what it was waiting for when the bound passes.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.graph.records import CLIENT, SERVER
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.session import visible

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.graph.cache import GraphCache
    from rosl.introspection.session import Session

DEFAULT_TIMEOUT = 5.0


def list_services(
    session: Session, *, show_types: bool = False, count: bool = False, include_hidden: bool = False
) -> list[str]:
    """The lines ``ros2 service list`` prints."""
    services = {n: t for n, t in session.graph().services().items() if visible(n, include_hidden)}
    if count:
        return [str(len(services))]
    return [f"{n} [{', '.join(t)}]" if show_types else n for n, t in services.items()]


def find_services(session: Session, type_name: str, *, include_hidden: bool = False) -> list[str]:
    """Services of a type (``pkg/srv/T`` or ``pkg/T``)."""
    from rosl.idl.names import canonical

    wanted = canonical(type_name, "srv")
    return [
        n for n, types in session.graph().services().items()
        if wanted in types and visible(n, include_hidden)
    ]  # fmt: skip


def service_info(session: Session, name: str) -> list[str]:
    """``ros2 service info`` (Jazzy): type, clients count, services count."""
    types = session.service_types(name)
    graph = session.graph()
    return [
        f"Type: {types[0] if len(types) == 1 else types}",
        f"Clients count: {graph.count(CLIENT, name)}",
        f"Services count: {graph.count(SERVER, name)}",
    ]


def resolve_service_type(session: Session, name: str, type_name: str | None) -> str:
    """The service type to use: the given one (``pkg/T`` allowed) or the graph's."""
    from rosl.idl.names import canonical

    if type_name:
        return canonical(type_name, "srv")
    return session.service_types(name)[0]


def _check_served_type(graph: GraphCache, name: str, wanted: str) -> None:
    """Fail at once when ``name`` is served, but only with other types than ``wanted``."""
    served = sorted({e.type for _, e in graph.endpoints(SERVER, name)})
    if served and wanted not in served:
        raise IntrospectionError(f"service {name} is of type {' and '.join(served)}, not {wanted}")


def _suggest(graph: GraphCache, name: str, wanted: str) -> str:
    """``; did you mean '/x'?``: the closest served names, those of type ``wanted`` first."""
    from rosl.idl.names import closest

    servers = graph.endpoints(SERVER)
    found = closest(name, {e.name for _, e in servers if e.type == wanted}, n=2)
    found = found or closest(name, {e.name for _, e in servers}, n=2)
    return "; did you mean " + " or ".join(f"'{c}'" for c in found) + "?" if found else ""


def call(
    session: Session,
    name: str,
    type_name: str | None,
    values: Any,
    *,
    rate: float | None = None,
    timeout: float = DEFAULT_TIMEOUT,
) -> Iterator[str]:
    """Call a service (repeatedly with ``rate``) and yield ros2's text for each call.

    Raises:
        IntrospectionError: bad type or values; the service is not there, or does not answer,
            within ``timeout`` seconds.
    """
    from rosl.idl.registry import get_service_class
    from rosl.introspection.publish import build
    from rosl.node.client import ServiceTimeoutError

    wanted = resolve_service_type(session, name, type_name)
    srv = get_service_class(wanted)
    request = build(srv.Request, values)
    _check_served_type(session.graph(), name, wanted)
    client = session.node().create_client(srv, name)
    if not client.service_is_ready():
        yield "waiting for service to become available..."
        graph = client.node.participant.graph
        if not client.wait_for_service(timeout_sec=timeout):
            raise IntrospectionError(
                f"service {name} not available after {float(timeout)} s"
                f"{_suggest(graph, name, wanted)}"
            )
        _check_served_type(graph, name, wanted)
    while True:
        started = time.monotonic()
        yield f"requester: making request: {request!r}\n"
        try:
            response = client.call(request, timeout_sec=timeout)
        except ServiceTimeoutError:
            raise IntrospectionError(
                f"service {name} did not answer within {timeout:g} s (request sent)"
            ) from None
        yield f"response:\n{response!r}\n"
        if not rate:
            return
        pause = 1.0 / rate - (time.monotonic() - started)
        if pause > 0:
            time.sleep(pause)


def echo(
    session: Session,
    name: str,
    type_name: str | None,
    *,
    truncate_length: int | None = 128,
    once: bool = False,
) -> Iterator[str]:
    """Yield each request and response of a service as a ``<Service>_Event`` (YAML + ``---``).

    Nothing has to be switched on in the nodes: service traffic is visible on the bus.
    """
    from rosl.bus.header import topic_hash
    from rosl.idl.yaml_io import dump_yaml, message_to_ordered
    from rosl.node.service_events import EVENT_NAMES, event_from_delivery

    service_type = resolve_service_type(session, name, type_name)
    participant = session.participant
    events: list[Any] = []

    class _Tap:
        def deliver(self, delivery: Any) -> None:
            event = event_from_delivery(delivery, service_type)
            if event is not None:
                events.append(event)

    participant.listen(topic_hash(name), _Tap())
    while not participant.closed:
        participant.poll(0.1)
        for event in events:
            data = message_to_ordered(event, truncate_length=truncate_length)
            data["info"]["event_type"] = EVENT_NAMES.get(data["info"]["event_type"], "UNKNOWN")
            yield dump_yaml(data) + "---"
            if once:
                return
        events.clear()
