"""``lifecycle nodes/list/get/set``: managed nodes, their states and transitions (ros2lifecycle).

A lifecycle node is one that serves ``<node>/get_state`` of type lifecycle_msgs/srv/GetState.
Each call is bounded (``timeout`` seconds, 5 by default; ros2 waits forever) and says what it
waited for. The texts are ros2lifecycle's; a node that is missing or not a lifecycle node, and a
transition the node does not offer, are one-line errors.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.errors import RoslError
from rosl.graph.records import SERVER
from rosl.idl.names import did_you_mean
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.session import visible

if TYPE_CHECKING:
    from rosl.graph.records import NodeRecord
    from rosl.introspection.session import Session

DEFAULT_TIMEOUT = 5.0
GET_STATE_TYPE = "lifecycle_msgs/srv/GetState"


def is_lifecycle_node(node: NodeRecord) -> bool:
    """Whether ``node`` serves ``<node>/get_state`` (lifecycle_msgs/srv/GetState)."""
    wanted = f"{node.fqn}/get_state"
    return any(
        e.kind == SERVER and e.name == wanted and e.type == GET_STATE_TYPE for e in node.endpoints
    )


def node_names(session: Session, *, include_hidden: bool = False) -> list[str]:
    """The lifecycle nodes of the graph, sorted."""
    return sorted(
        {
            n.fqn
            for n in session.graph().nodes()
            if visible(n.fqn, include_hidden) and is_lifecycle_node(n)
        }
    )


def list_nodes(session: Session, *, include_hidden: bool = False, count: bool = False) -> list[str]:
    """The lines ``ros2 lifecycle nodes`` prints."""
    names = node_names(session, include_hidden=include_hidden)
    return [str(len(names))] if count else names


def _absolute(name: str) -> str:
    return name if name.startswith("/") else "/" + name


def lifecycle_node(session: Session, name: str, *, include_hidden: bool = False) -> str:
    """``name`` as a full name, checked to be a lifecycle node of the graph.

    Raises:
        IntrospectionError: ros2's "Node not found", with why and the closest lifecycle node.
    """
    fqn = _absolute(name)
    managed = node_names(session, include_hidden=include_hidden)
    if fqn in managed:
        return fqn
    if session.graph().find_node(fqn) and visible(fqn, include_hidden):
        raise IntrospectionError(
            f"Node not found: {fqn} is not a lifecycle node (it serves no {fqn}/get_state)"
        )
    raise IntrospectionError(f"Node not found: {fqn}{did_you_mean(fqn, managed)}")


def _call(session: Session, name: str, type_name: str, request: Any, timeout: float) -> Any:
    """Call one service and return its response (bounded by ``timeout``)."""
    import rosl
    from rosl.idl.registry import get_service_class

    node = session.node()
    client = node.create_client(get_service_class(type_name), name)
    deadline = time.monotonic() + timeout
    while not client.service_is_ready():
        left = deadline - time.monotonic()
        if left <= 0 or not node.context.ok():
            raise IntrospectionError(f"service {name} not available after {timeout:g} s")
        client.wait_for_service(timeout_sec=min(left, 0.1))
    future = client.call_async(request if request is not None else client.srv_type.Request())
    while not future.done():
        left = deadline - time.monotonic()
        if left <= 0 or not node.context.ok():
            client.remove_pending_request(future)
            raise IntrospectionError(f"service {name} did not answer within {timeout:g} s")
        rosl.spin_once(node, timeout_sec=min(left, 0.1))
    return future.result()


def get_states(
    session: Session,
    name: str | None,
    *,
    include_hidden: bool = False,
    timeout: float = DEFAULT_TIMEOUT,
) -> tuple[list[str], list[str]]:
    """``ros2 lifecycle get [NODE]``: (stdout lines, stderr lines).

    One node: ``label [id]`` (a node that does not answer is an error). Every node: ``/node:
    label [id]`` each, and a node that does not answer is a line on stderr, as ros2 has it.
    """
    if name:
        fqn = lifecycle_node(session, name, include_hidden=include_hidden)
        state = _call(session, f"{fqn}/get_state", GET_STATE_TYPE, None, timeout).current_state
        return [f"{state.label} [{state.id}]"], []
    lines, problems = [], []
    for fqn in node_names(session, include_hidden=include_hidden):
        try:
            response = _call(session, f"{fqn}/get_state", GET_STATE_TYPE, None, timeout)
        except RoslError as err:
            problems.append(f"Exception while calling service of node '{fqn}': {err}")
            continue
        lines.append(f"{fqn}: {response.current_state.label} [{response.current_state.id}]")
    return lines, problems


def transitions(
    session: Session, fqn: str, *, graph: bool = False, timeout: float = DEFAULT_TIMEOUT
) -> list[Any]:
    """The transitions a lifecycle node offers now (``graph``: all of them)."""
    service = "get_transition_graph" if graph else "get_available_transitions"
    response = _call(
        session, f"{fqn}/{service}", "lifecycle_msgs/srv/GetAvailableTransitions", None, timeout
    )
    return list(response.available_transitions)


def list_transitions(
    session: Session,
    name: str,
    *,
    show_all: bool = False,
    include_hidden: bool = False,
    timeout: float = DEFAULT_TIMEOUT,
) -> list[str]:
    """``ros2 lifecycle list NODE [-a]``: each transition with its start and goal state."""
    fqn = lifecycle_node(session, name, include_hidden=include_hidden)
    lines = []
    for t in transitions(session, fqn, graph=show_all, timeout=timeout):
        lines += [
            f"- {t.transition.label} [{t.transition.id}]",
            f"\tStart: {t.start_state.label}",
            f"\tGoal: {t.goal_state.label}",
        ]
    return lines


def set_state(
    session: Session,
    name: str,
    transition: str,
    *,
    include_hidden: bool = False,
    timeout: float = DEFAULT_TIMEOUT,
) -> str:
    """``ros2 lifecycle set NODE TRANSITION`` (a label, or an id): 'Transitioning successful'.

    Raises:
        IntrospectionError: unknown node or transition (naming the ones on offer); the node
            answered that the transition failed ('Transitioning failed').
    """
    fqn = lifecycle_node(session, name, include_hidden=include_hidden)
    offered = [t.transition for t in transitions(session, fqn, timeout=timeout)]
    chosen = next((t for t in offered if t.label == transition), None)
    chosen = chosen or next((t for t in offered if str(t.id) == transition), None)
    if chosen is None:
        listed = ", ".join(f"{t.label} [{t.id}]" for t in offered) or "none"
        raise IntrospectionError(f"Unknown transition requested, available ones are: {listed}")
    from rosl.idl.registry import get_service_class

    request: Any = get_service_class("lifecycle_msgs/srv/ChangeState").Request()
    request.transition.id, request.transition.label = chosen.id, chosen.label
    response = _call(
        session, f"{fqn}/change_state", "lifecycle_msgs/srv/ChangeState", request, timeout
    )
    if not response.success:
        raise IntrospectionError("Transitioning failed")
    return "Transitioning successful"
