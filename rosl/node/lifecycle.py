"""Managed (lifecycle) nodes (rclpy.lifecycle.LifecycleNode): transitions, callbacks, services.

A lifecycle node is a Node with rcl_lifecycle's state machine. A transition moves it into a
transition state, runs the callback of that state (``on_configure`` for configuring, ...; the
default ones pass the call on to the managed entities, lifecycle publishers among them), then
takes ``transition_success``, ``transition_failure`` or ``transition_error`` by the answer; an
error runs ``on_error`` in errorprocessing, whose answer leads to unconfigured or finalized. A
callback that raises answers ERROR (the exception is logged).

Unless ``enable_communication_interface=False``, the node serves ``~/change_state``,
``~/get_state``, ``~/get_available_states``, ``~/get_available_transitions`` and
``~/get_transition_graph``, and publishes each state change on ``~/transition_event``
(lifecycle_msgs/msg/TransitionEvent, start and goal state filled, as rcl_lifecycle sends it).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class, get_service_class
from rosl.node.errors import LifecycleTransitionError
from rosl.node.lifecycle_machine import (
    ACTIVATING,
    CLEANINGUP,
    CONFIGURING,
    DEACTIVATING,
    ERRORPROCESSING,
    SHUTDOWN_FROM,
    SHUTTINGDOWN,
    StateInfo,
    StateMachine,
    TransitionInfo,
)
from rosl.node.managed import (
    LifecyclePublisher,
    LifecycleState,
    ManagedEntity,
    TransitionCallbackReturn,
)
from rosl.node.node import Node

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.publisher import Publisher

_CALLBACK_OF_STATE = {
    CONFIGURING.id: "on_configure",
    CLEANINGUP.id: "on_cleanup",
    SHUTTINGDOWN.id: "on_shutdown",
    ACTIVATING.id: "on_activate",
    DEACTIVATING.id: "on_deactivate",
    ERRORPROCESSING.id: "on_error",
}
_SERVICES = (
    ("change_state", "ChangeState"),
    ("get_state", "GetState"),
    ("get_available_states", "GetAvailableStates"),
    ("get_available_transitions", "GetAvailableTransitions"),
    ("get_transition_graph", "GetAvailableTransitions"),
)


class LifecycleNodeMixin(ManagedEntity):
    """The lifecycle part of LifecycleNode, for a class that is also a Node."""

    def __init__(
        self,
        *,
        enable_communication_interface: bool = True,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        if not isinstance(enable_communication_interface, bool):
            raise TypeError("enable_communication_interface must be a bool")
        assert isinstance(self, Node)
        self._state_machine = StateMachine()
        self._managed_entities: dict[ManagedEntity, None] = {}  # an ordered set
        self._transition_lock = threading.RLock()
        self._transition_events: Publisher | None = None
        if enable_communication_interface:
            self._transition_events = self.create_publisher(
                get_message_class("lifecycle_msgs/msg/TransitionEvent"), "~/transition_event", 10
            )
            handlers: dict[str, Callable[[Any, Any], Any]] = {
                "change_state": self._on_change_state,
                "get_state": self._on_get_state,
                "get_available_states": self._on_get_available_states,
                "get_available_transitions": self._on_get_available_transitions,
                "get_transition_graph": self._on_get_transition_graph,
            }
            for name, srv in _SERVICES:
                service = self.create_service(
                    get_service_class(f"lifecycle_msgs/srv/{srv}"), f"~/{name}",
                    handlers[name], callback_group=callback_group,
                )  # fmt: skip
                setattr(self, f"_service_{name}", service)

    # --- transitions -------------------------------------------------------------------------

    def trigger_configure(self) -> TransitionCallbackReturn:
        """Take the configure transition (unconfigured -> inactive on SUCCESS)."""
        return self._change_state(1)

    def trigger_cleanup(self) -> TransitionCallbackReturn:
        """Take the cleanup transition (inactive -> unconfigured on SUCCESS)."""
        return self._change_state(2)

    def trigger_activate(self) -> TransitionCallbackReturn:
        """Take the activate transition (inactive -> active on SUCCESS)."""
        return self._change_state(3)

    def trigger_deactivate(self) -> TransitionCallbackReturn:
        """Take the deactivate transition (active -> inactive on SUCCESS)."""
        return self._change_state(4)

    def trigger_shutdown(self) -> TransitionCallbackReturn | None:
        """Take the shutdown transition of the current primary state (-> finalized)."""
        transition_id = SHUTDOWN_FROM.get(self._state_machine.current.label)
        return None if transition_id is None else self._change_state(transition_id)

    def _change_state(self, transition_id: int) -> TransitionCallbackReturn:
        """Run one requested transition: callback, outcome, and on_error after an ERROR.

        Raises:
            LifecycleTransitionError: the transition does not start in the current state.
        """
        machine = self._state_machine
        with self._transition_lock:
            try:
                transition = machine.transition_by_id(transition_id)
            except LifecycleTransitionError as err:
                self._logger_warn(str(err))
                raise
            initial = LifecycleState(label=machine.current.label, state_id=machine.current.id)
            self._take(transition)
            answer = self._run_callback(machine.current, initial)
            self._take(machine.transition_by_label(answer.to_label()))
            if answer is TransitionCallbackReturn.ERROR:
                on_error = self._run_callback(machine.current, initial)
                self._take(machine.transition_by_label(on_error.to_label()))
            return answer

    def _take(self, transition: TransitionInfo) -> None:
        start, goal = self._state_machine.take(transition)
        if self._transition_events is not None:
            event: Any = self._transition_events.msg_type()
            event.start_state.id, event.start_state.label = start
            event.goal_state.id, event.goal_state.label = goal
            self._transition_events.publish(event)

    def _run_callback(self, state: StateInfo, previous: LifecycleState) -> TransitionCallbackReturn:
        name = _CALLBACK_OF_STATE.get(state.id)
        if name is None:
            return TransitionCallbackReturn.SUCCESS
        try:
            answer = getattr(self, name)(previous)
        except Exception as err:
            self._logger_error(f"{name}() raised {type(err).__name__}: {err}")
            return TransitionCallbackReturn.ERROR
        if not isinstance(answer, TransitionCallbackReturn):
            self._logger_error(
                f"{name}() returned {answer!r}, not a TransitionCallbackReturn: taken as ERROR"
            )
            return TransitionCallbackReturn.ERROR
        return answer

    def _logger_warn(self, text: str) -> None:
        assert isinstance(self, Node)
        self.get_logger().warning(text)

    def _logger_error(self, text: str) -> None:
        assert isinstance(self, Node)
        self.get_logger().error(text)

    # --- managed entities --------------------------------------------------------------------

    def add_managed_entity(self, entity: ManagedEntity) -> None:
        """Have ``entity``'s transition callbacks called by the default ones."""
        self._managed_entities[entity] = None

    def _entities_answer(self, name: str, state: LifecycleState) -> TransitionCallbackReturn:
        """Call each managed entity's ``name`` callback; the first answer not SUCCESS wins."""
        for entity in list(self._managed_entities):
            answer: TransitionCallbackReturn = getattr(entity, name)(state)
            if answer != TransitionCallbackReturn.SUCCESS:
                return answer
        return TransitionCallbackReturn.SUCCESS

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Configure the managed entities (override, calling super(), to do more)."""
        return self._entities_answer("on_configure", state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Clean up the managed entities."""
        return self._entities_answer("on_cleanup", state)

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Shut down the managed entities."""
        return self._entities_answer("on_shutdown", state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Activate the managed entities (lifecycle publishers start sending)."""
        return self._entities_answer("on_activate", state)

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Deactivate the managed entities (lifecycle publishers stop sending)."""
        return self._entities_answer("on_deactivate", state)

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle an error of the managed entities."""
        return self._entities_answer("on_error", state)

    def create_lifecycle_publisher(self, *args: Any, **kwargs: Any) -> LifecyclePublisher:
        """A publisher that sends only while the node is active (a managed entity)."""
        if "publisher_class" in kwargs:
            raise TypeError(
                "create_lifecycle_publisher() got an unexpected keyword argument 'publisher_class'"
            )
        assert isinstance(self, Node)
        publisher = Node.create_publisher(self, *args, **kwargs, publisher_class=LifecyclePublisher)
        assert isinstance(publisher, LifecyclePublisher)
        self._managed_entities[publisher] = None  # enabled by the next activate, as in rclpy
        return publisher

    def destroy_lifecycle_publisher(self, publisher: LifecyclePublisher) -> bool:
        """Destroy a lifecycle publisher."""
        self._managed_entities.pop(publisher, None)
        assert isinstance(self, Node)
        return Node.destroy_publisher(self, publisher)

    # --- services ----------------------------------------------------------------------------

    def _on_change_state(self, request: Any, response: Any) -> Any:
        transition_id = request.transition.id
        with self._transition_lock:
            if request.transition.label:
                try:
                    found = self._state_machine.transition_by_label(request.transition.label)
                except LifecycleTransitionError as err:
                    self._logger_warn(str(err))
                    response.success = False
                    return response
                transition_id = found.id
            try:
                answer = self._change_state(transition_id)
            except LifecycleTransitionError:
                response.success = False
                return response
        response.success = answer is TransitionCallbackReturn.SUCCESS
        return response

    def _on_get_state(self, request: Any, response: Any) -> Any:
        response.current_state.id, response.current_state.label = self._state_machine.current
        return response

    def _on_get_available_states(self, request: Any, response: Any) -> Any:
        state_type = get_message_class("lifecycle_msgs/msg/State")
        response.available_states = [
            state_type(id=s.id, label=s.label) for s in self._state_machine.available_states
        ]
        return response

    def _on_get_available_transitions(self, request: Any, response: Any) -> Any:
        response.available_transitions = _descriptions(self._state_machine.available_transitions)
        return response

    def _on_get_transition_graph(self, request: Any, response: Any) -> Any:
        response.available_transitions = _descriptions(self._state_machine.transition_graph)
        return response


LifecycleMixin = LifecycleNodeMixin  # the later distros' name


def _descriptions(transitions: Iterable[TransitionInfo]) -> list[Any]:
    """lifecycle_msgs/msg/TransitionDescription messages."""
    description = get_message_class("lifecycle_msgs/msg/TransitionDescription")
    out = []
    for t in transitions:
        item: Any = description()
        item.transition.id, item.transition.label = t.id, t.label
        item.start_state.id, item.start_state.label = t.start
        item.goal_state.id, item.goal_state.label = t.goal
        out.append(item)
    return out


class LifecycleNode(LifecycleNodeMixin, Node):
    """A managed node (rclpy.lifecycle.LifecycleNode): a Node with lifecycle transitions."""

    def __init__(
        self,
        node_name: str,
        *,
        enable_communication_interface: bool = True,
        **kwargs: Any,
    ) -> None:
        Node.__init__(self, node_name, **kwargs)
        LifecycleNodeMixin.__init__(
            self, enable_communication_interface=enable_communication_interface
        )
