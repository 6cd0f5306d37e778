"""``action list/info/type/send_goal`` in ros2action's words.

``send_goal`` waits a bounded time for the server (ros2 waits forever) and says what it waited
for; the goal's own run is not bounded (a goal may rightly take long), and Ctrl-C cancels the
goal on the server before the command ends, as ros2 does.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.graph import actions
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from collections.abc import Generator, Iterator

    from rosl.introspection.session import Session
    from rosl.node.task import Future

DEFAULT_TIMEOUT = 5.0


def list_actions(session: Session, *, show_types: bool = False, count: bool = False) -> list[str]:
    """The lines ``ros2 action list`` prints."""
    found = actions.names_and_types(session.graph())
    if count:
        return [str(len(found))]
    return [f"{n} [{', '.join(t)}]" if show_types else n for n, t in found.items()]


def action_info(
    session: Session, name: str, *, show_types: bool = False, count: bool = False
) -> list[str]:
    """The lines ``ros2 action info ACTION`` prints: its clients' and servers' nodes."""
    wanted = name if name.startswith("/") else "/" + name
    users: dict[str, list[tuple[str, list[str]]]] = {"clients": [], "servers": []}
    for node in session.graph().nodes():
        for kind, entries in (
            ("clients", actions.clients(node)),
            ("servers", actions.servers(node)),
        ):
            if wanted in entries:
                users[kind].append((node.fqn, entries[wanted]))
    lines = [f"Action: {name}"]
    for kind in ("clients", "servers"):
        lines.append(f"Action {kind}: {len(users[kind])}")
        if not count:
            lines += [
                f"    {fqn} [{', '.join(types)}]" if show_types else f"    {fqn}"
                for fqn, types in users[kind]
            ]
    return lines


def action_types(session: Session, name: str) -> list[str]:
    """The types of an action (empty when there is no such action)."""
    return actions.names_and_types(session.graph()).get(name, [])


def _yaml(message: Any) -> str:
    from rosl.idl.yaml_io import message_to_yaml

    return message_to_yaml(message)


def send_goal(
    session: Session,
    name: str,
    type_name: str,
    values: Any,
    *,
    feedback: bool = False,
    timeout: float = DEFAULT_TIMEOUT,
) -> Iterator[str]:
    """Send one goal and yield ros2's text as it goes (each item is printed as one ``print``).

    Raises:
        IntrospectionError: bad type or values, or no server within ``timeout`` seconds.
    """
    from rosl.idl.registry import get_action_class
    from rosl.introspection.publish import build
    from rosl.node.action_client import ActionClient

    action = get_action_class(type_name)
    goal = build(action.Goal, values)
    node = session.node()
    client = ActionClient(node, action, name)
    shown: list[str] = []

    def on_feedback(message: Any) -> None:
        shown.append(f"Feedback:\n    {_yaml(message.feedback)}")

    yield "Waiting for an action server to become available..."
    deadline = time.monotonic() + timeout
    while not client.server_is_ready():
        if not node.context.ok():
            return
        if time.monotonic() >= deadline:
            raise IntrospectionError(
                f"action server {client.action_name} ({type_name}) not available after "
                f"{float(timeout)} s"
            )
        client.wait_for_server(timeout_sec=0.1)
    yield f"Sending goal:\n     {_yaml(goal)}"
    sent = client.send_goal_async(goal, on_feedback if feedback else None)
    handle = yield from _spin(node, sent, shown)
    if handle is None:
        return
    if not handle.accepted:
        yield "Goal was rejected."
        return
    yield f"Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n"
    result = yield from _spin(node, handle.get_result_async(), shown, last=True)
    if result is None:
        yield from _cancel(node, handle)
        return
    from rosl.node.action_goals import status_word

    yield f"Result:\n    {_yaml(result.result)}"
    yield f"Goal finished with status: {status_word(result.status)}"


def _spin(
    node: Any, future: Future[Any], shown: list[str], *, last: bool = False
) -> Generator[str, None, Any]:
    """Serve the node until ``future`` is done (its result) or Ctrl-C (None), yielding feedback.

    Feedback that came with the goal's response waits for the next call (after the 'Goal
    accepted' line); the ``last`` call yields all of it before returning.
    """
    import rosl

    while not future.done():
        if not node.context.ok():
            return None
        rosl.spin_once(node, timeout_sec=0.1)
        while shown and not future.done():
            yield shown.pop(0)
    while shown and last:
        yield shown.pop(0)
    return future.result()


def _cancel(node: Any, handle: Any) -> Iterator[str]:
    """After Ctrl-C: cancel a goal still running (ros2's 'Canceling goal...', bounded)."""
    from rosl.node.action_goals import ACTIVE

    if handle.status not in ACTIVE:
        return
    yield "Canceling goal..."
    future = handle.cancel_goal_async()
    client = handle._action_client._cancel_client

    def answered() -> bool:  # the context is shutting down: read the answer ourselves
        while client._take() is not None:
            pass
        return bool(future.done())

    node.participant.wait(answered, DEFAULT_TIMEOUT)
    response = future.result() if future.done() else None
    if response is None or not response.goals_canceling:
        raise IntrospectionError("Failed to cancel goal")
    yield "Goal canceled."
