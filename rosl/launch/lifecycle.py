"""launch_ros.actions.LifecycleNode: a Node whose transitions the launch can drive and watch.

The launcher gets one hidden node of its own (``_rosl_launch_<pid>``, on a thread, in a context
of its own) as soon as a LifecycleNode runs: it listens to each lifecycle node's
``<node>/transition_event`` (each message becomes a StateTransition event on the supervising
loop) and calls its ``<node>/change_state`` when a ChangeState event asks (one request at a time
per node, sent once the service is there; a refused transition is logged as launch_ros does).
``autostart=True`` (launch_ros' later distros) asks for configure, then activate;
LifecycleTransition asks named nodes for a list of transitions.
"""

from __future__ import annotations

import collections
import os
import threading
from typing import TYPE_CHECKING, Any

from rosl.launch.description import Action
from rosl.launch.errors import LaunchError
from rosl.launch.lifecycle_events import ChangeState, StateTransition
from rosl.launch.ros_actions import Node, _shown, _user_site
from rosl.launch.substitutions import perform

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext
    from rosl.launch.records import ProcessEvent, ShutdownEvent
    from rosl.launch.supervisor import Supervisor
    from rosl.node.node import Node as RosNode

_LOGGER = "launch_ros.actions.lifecycle_node"


class LifecycleNode(Node):
    """Start a lifecycle node (launch_ros.actions.LifecycleNode); ``name`` is required."""

    def __init__(
        self,
        *,
        name: Any = None,
        namespace: Any = None,
        autostart: Any = False,
        node_name: Any = None,
        **kwargs: Any,
    ) -> None:
        name = name if name is not None else node_name
        if name is None:
            executable = kwargs.get("executable")
            shown = f"(executable='{_shown(executable)}')" if executable is not None else "()"
            raise LaunchError(f"{_user_site()}LifecycleNode{shown} needs name=")
        super().__init__(name=name, namespace=namespace, **kwargs)
        self.autostart = autostart
        self.lifecycle_node_name = ""

    @property
    def is_lifecycle_node(self) -> bool:
        """A LifecycleNode is one (OnStateTransition checks it)."""
        return True

    def execute(self, context: LaunchContext) -> None:
        """Start watching the node's transitions, then start it as a Node."""
        namespace = self._namespace(context).rstrip("/")
        self.lifecycle_node_name = f"{namespace}/{perform(context, self.node_name)}"
        supervisor = context.supervisor
        if supervisor is not None and not supervisor.dry_run:
            manager = LifecycleManager.of(supervisor, context)
            manager.watch(self)
            if _truthy(context, self.autostart):
                batch = object()
                manager.change_state(self, 1, batch)
                manager.change_state(self, 3, batch)
        super().execute(context)


def _truthy(context: LaunchContext, value: Any) -> bool:
    if value is None or isinstance(value, bool):
        return bool(value)
    return perform(context, value).strip().lower() in ("true", "1", "yes")


class _Request:
    """One ChangeState request waiting to be sent or answered (``batch``: dropped if one fails)."""

    def __init__(self, action: LifecycleNode, transition_id: int, batch: object = None) -> None:
        self.action = action
        self.transition_id = transition_id
        self.batch = batch
        self.future: Any = None


class LifecycleManager:
    """The launcher's node for its lifecycle nodes: transition events in, change_state out."""

    def __init__(self, supervisor: Supervisor) -> None:
        self.supervisor = supervisor
        self._actions: list[LifecycleNode] = []
        self._jobs: collections.deque[Any] = collections.deque()
        self._requests: list[_Request] = []
        self._clients: dict[int, Any] = {}
        self._stop = threading.Event()
        self._node: RosNode | None = None
        # the node is made on a thread this one waits for: its context installs no signal
        # handlers there, and whatever it imports registers its fork handlers before, not
        # while, the launcher starts a process
        maker = threading.Thread(target=self._make_node, name="rosl-lifecycle-setup")
        maker.start()
        maker.join()
        self._thread = threading.Thread(target=self._run, name="rosl-lifecycle", daemon=True)
        self._thread.start()

    @classmethod
    def of(cls, supervisor: Supervisor, context: LaunchContext) -> LifecycleManager:
        """The supervisor's manager (started on first use, stopped when the launch ends)."""
        manager: LifecycleManager | None = getattr(supervisor, "lifecycle_manager", None)
        if manager is None:
            manager = cls(supervisor)
            supervisor.lifecycle_manager = manager  # type: ignore[attr-defined]
            supervisor.add_handler(_StopAtShutdown(manager), context)
        return manager

    @staticmethod
    def find(context: LaunchContext) -> LifecycleManager | None:
        """The manager of the launch, if a LifecycleNode started one."""
        return getattr(context.supervisor, "lifecycle_manager", None)

    def actions(self) -> list[LifecycleNode]:
        """The LifecycleNode actions run so far."""
        return list(self._actions)

    def watch(self, action: LifecycleNode) -> None:
        """Listen to the node's transition events and get ready to call its change_state."""
        self._actions.append(action)
        self._jobs.append(lambda node: self._setup(node, action))

    def change_state(self, action: LifecycleNode, transition_id: int, batch: object = None) -> None:
        """Ask the node for a transition (after the requests already asked of it).

        Requests of one ``batch`` that follow a refused one are dropped.
        """
        request = _Request(action, transition_id, batch)
        self._jobs.append(lambda node: self._requests.append(request))

    def stop(self) -> None:
        """Leave the bus (the thread ends within 0.1 s)."""
        self._stop.set()

    # --- the thread ----------------------------------------------------------------------------

    def _make_node(self) -> None:
        import rosl.node.client
        import rosl.node.subscription
        import rosl.node.task  # noqa: F401 - imported before any fork, see __init__
        from rosl.executor import SingleThreadedExecutor
        from rosl.idl.registry import get_message_class, get_service_class
        from rosl.node.context import Context
        from rosl.node.node import Node as RosNode

        get_message_class("lifecycle_msgs/msg/TransitionEvent")
        get_service_class("lifecycle_msgs/srv/ChangeState")
        context = Context()
        context.init([])  # not the main thread: the launcher keeps its signal handlers
        self._node = RosNode(
            f"_rosl_launch_{os.getpid()}", context=context,
            start_parameter_services=False, enable_rosout=False,
        )  # fmt: skip
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self._node)

    def _run(self) -> None:
        node = self._node
        assert node is not None
        try:
            while not self._stop.is_set():
                while self._jobs:
                    self._jobs.popleft()(node)
                self._serve_requests()
                self._executor.spin_once(timeout_sec=0.05)
        finally:
            node.context.try_shutdown()

    def _setup(self, node: RosNode, action: LifecycleNode) -> None:
        from rosl.idl.registry import get_message_class, get_service_class

        name = action.lifecycle_node_name
        node.create_subscription(
            get_message_class("lifecycle_msgs/msg/TransitionEvent"), f"{name}/transition_event",
            lambda msg: self._on_transition_event(action, msg), 10,
        )  # fmt: skip
        self._clients[id(action)] = node.create_client(
            get_service_class("lifecycle_msgs/srv/ChangeState"), f"{name}/change_state"
        )

    def _on_transition_event(self, action: LifecycleNode, msg: Any) -> None:
        event = StateTransition(action=action, msg=msg)
        self.supervisor.call_soon_threadsafe(lambda: self.supervisor.emit(event))

    def _serve_requests(self) -> None:
        """Send each node's oldest request once its service is there; handle the answers."""
        busy: set[int] = set()
        for request in list(self._requests):
            key = id(request.action)
            if key in busy or request not in self._requests:  # (dropped by a refusal meanwhile)
                continue
            busy.add(key)
            client = self._clients[key]
            if request.future is None and client.service_is_ready():
                message = client.srv_type.Request()
                message.transition.id = request.transition_id
                request.future = client.call_async(message)
            elif request.future is not None and request.future.done():
                self._requests.remove(request)
                busy.discard(key)
                self._answered(request)

    def _answered(self, request: _Request) -> None:
        try:
            success = bool(request.future.result().success)
        except Exception as err:  # the node's callback failed: its one line
            success, why = False, f": {err}"
        else:
            why = ""
        if not success:
            if request.batch is not None:
                self._requests = [r for r in self._requests if r.batch is not request.batch]
            label = ChangeState.valid_transitions.get(request.transition_id, request.transition_id)
            text = (
                f"Failed to make transition '{label}' for LifecycleNode "
                f"'{request.action.lifecycle_node_name}'{why}"
            )
            self.supervisor.call_soon_threadsafe(
                lambda: self.supervisor.log("ERROR", _LOGGER, text)
            )


class LifecycleTransition(Action):
    """Take transitions of lifecycle nodes by name, one after the other (launch_ros, Jazzy).

    Each node takes ``transition_ids`` in order, the next once the previous one is done; a
    refused transition drops the rest for that node (and is logged).
    """

    def __init__(
        self, *, lifecycle_node_names: list[Any], transition_ids: list[Any], **kwargs: Any
    ) -> None:
        super().__init__(**kwargs)
        if not transition_ids:
            raise LaunchError(f"{_user_site()}LifecycleTransition: no transition_ids provided")
        if not lifecycle_node_names:
            raise LaunchError(
                f"{_user_site()}LifecycleTransition: no lifecycle_node_names provided"
            )
        self.lifecycle_node_names = list(lifecycle_node_names)
        self.transition_ids = list(transition_ids)

    def execute(self, context: LaunchContext) -> None:
        """Queue the transitions of each named lifecycle node the launch started."""
        names = {"/" + perform(context, n).lstrip("/") for n in self.lifecycle_node_names}
        ids = []
        for value in self.transition_ids:
            text = str(value) if isinstance(value, int) else perform(context, value)
            if not text.strip().isdigit() or int(text) not in ChangeState.valid_transitions:
                raise LaunchError(f"LifecycleTransition: '{text}' is not a lifecycle transition id")
            ids.append(int(text))
        manager = LifecycleManager.find(context)
        if manager is None:
            return
        for action in manager.actions():
            if action.lifecycle_node_name in names:
                batch = object()
                for transition_id in ids:
                    manager.change_state(action, transition_id, batch)


class _StopAtShutdown:
    """Stops the manager when the launch shuts down (a handler of the shutdown event)."""

    kinds = ("shutdown",)

    def __init__(self, manager: LifecycleManager) -> None:
        self.manager = manager

    def matches(self, event: ProcessEvent | ShutdownEvent) -> bool:
        return event.kind == "shutdown"

    def entities(self, event: Any, context: LaunchContext) -> list[Any]:
        self.manager.stop()
        return []
