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
    """Services of a type (``pkg/srv/T`` or ``pkg/T``; any other text matches no type)."""
    from rosl.idl.errors import InterfaceError
    from rosl.idl.names import canonical

    try:
        wanted = canonical(type_name, "srv")
    except InterfaceError:
        return []  # as ros2: a name that is no type finds nothing
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
        ServiceFailedError: the server's callback raised (its one-line report, at once).
    """
    from rosl.idl.registry import get_service_class
    from rosl.introspection.publish import build

    wanted = resolve_service_type(session, name, type_name)
    srv = get_service_class(wanted)
    request = build(srv.Request, values)
    _check_served_type(session.graph(), name, wanted)
    client = session.node().create_client(srv, name)
    context = client.node.context  # its first Ctrl-C ends the command (ok() turns false)
    if not client.service_is_ready():
        yield "waiting for service to become available..."
        graph = client.node.participant.graph
        if not _wait_service(client, timeout):
            if not context.ok():
                return
            raise IntrospectionError(
                f"service {name} not available after {float(timeout)} s"
                f"{_suggest(graph, name, wanted)}"
            )
        _check_served_type(graph, name, wanted)
    while context.ok():
        started = time.monotonic()
        yield f"requester: making request: {request!r}\n"
        response = _answer(client, name, request, timeout)
        if response is _INTERRUPTED:
            return
        yield f"response:\n{response!r}\n"
        if not rate:
            return
        _pause_until(client.node, started + 1.0 / rate)


_INTERRUPTED = object()


def _wait_service(client: Any, timeout: float) -> bool:
    """Wait (bounded, and ended by Ctrl-C) for a server; return whether there is one."""
    deadline = time.monotonic() + timeout
    while not client.service_is_ready():
        left = deadline - time.monotonic()
        if left <= 0 or not client.node.context.ok():
            return False
        client.wait_for_service(timeout_sec=min(left, 0.1))
    return True


def _answer(client: Any, name: str, request: Any, timeout: float) -> Any:
    """The response to one call; ``_INTERRUPTED`` after Ctrl-C.

    Raises:
        IntrospectionError: no answer within ``timeout`` seconds.
        ServiceFailedError: the server's callback raised.
    """
    import rosl

    future = client.call_async(request)
    deadline = time.monotonic() + timeout
    while not future.done():
        left = deadline - time.monotonic()
        if left <= 0 or not client.node.context.ok():
            client.remove_pending_request(future)
            if left > 0:
                return _INTERRUPTED
            raise IntrospectionError(
                f"service {name} did not answer within {timeout:g} s (request sent)"
            )
        rosl.spin_once(client.node, timeout_sec=min(left, 0.1))
    return future.result()


def _pause_until(node: Any, when: float) -> None:
    """Serve the node until ``when`` (monotonic), or until Ctrl-C."""
    import rosl

    while node.context.ok() and (left := when - time.monotonic()) > 0:
        rosl.spin_once(node, timeout_sec=min(left, 0.1))


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
