"""The managed-node state machine as rcl_lifecycle defines it: states, transitions, moves.

Primary states (unconfigured, inactive, active, finalized), transition states (configuring,
cleaningup, shuttingdown, activating, deactivating, errorprocessing) and the transitions between
them, with lifecycle_msgs' ids and rcl_lifecycle's labels: the requested ones are ``configure``,
``cleanup``, ``activate``, ``deactivate`` and ``shutdown`` (three of them, one per primary state);
a callback's outcome leaves a transition state by ``transition_success``, ``transition_failure``
or ``transition_error``. Pure data and bookkeeping: no bus, no callbacks.
"""

from __future__ import annotations

from typing import NamedTuple

from rosl.node.errors import LifecycleTransitionError


class StateInfo(NamedTuple):
    """A state: lifecycle_msgs/msg/State's id and rcl_lifecycle's label."""

    id: int
    label: str


class TransitionInfo(NamedTuple):
    """A transition from one state to another (lifecycle_msgs/msg/TransitionDescription)."""

    id: int
    label: str
    start: StateInfo
    goal: StateInfo


UNKNOWN = StateInfo(0, "unknown")
UNCONFIGURED = StateInfo(1, "unconfigured")
INACTIVE = StateInfo(2, "inactive")
ACTIVE = StateInfo(3, "active")
FINALIZED = StateInfo(4, "finalized")
CONFIGURING = StateInfo(10, "configuring")
CLEANINGUP = StateInfo(11, "cleaningup")
SHUTTINGDOWN = StateInfo(12, "shuttingdown")
ACTIVATING = StateInfo(13, "activating")
DEACTIVATING = StateInfo(14, "deactivating")
ERRORPROCESSING = StateInfo(15, "errorprocessing")

# in rcl_lifecycle's order of registration (what get_available_states answers)
STATES = (
    UNKNOWN, UNCONFIGURED, INACTIVE, ACTIVE, FINALIZED,
    CONFIGURING, CLEANINGUP, SHUTTINGDOWN, ACTIVATING, DEACTIVATING, ERRORPROCESSING,
)  # fmt: skip

SUCCESS_LABEL = "transition_success"
FAILURE_LABEL = "transition_failure"
ERROR_LABEL = "transition_error"


def _outcomes(
    first_id: int, state: StateInfo, success: StateInfo, failure: StateInfo, error: StateInfo
) -> list[TransitionInfo]:
    """The three ways out of a transition state (ids N0, N1, N2 as lifecycle_msgs numbers)."""
    return [
        TransitionInfo(first_id, SUCCESS_LABEL, state, success),
        TransitionInfo(first_id + 1, FAILURE_LABEL, state, failure),
        TransitionInfo(first_id + 2, ERROR_LABEL, state, error),
    ]


# in rcl_lifecycle's order of registration (what get_transition_graph answers)
TRANSITIONS: tuple[TransitionInfo, ...] = (
    TransitionInfo(1, "configure", UNCONFIGURED, CONFIGURING),
    *_outcomes(10, CONFIGURING, INACTIVE, UNCONFIGURED, ERRORPROCESSING),
    TransitionInfo(2, "cleanup", INACTIVE, CLEANINGUP),
    *_outcomes(20, CLEANINGUP, UNCONFIGURED, INACTIVE, ERRORPROCESSING),
    TransitionInfo(3, "activate", INACTIVE, ACTIVATING),
    *_outcomes(30, ACTIVATING, ACTIVE, INACTIVE, ERRORPROCESSING),
    TransitionInfo(4, "deactivate", ACTIVE, DEACTIVATING),
    *_outcomes(40, DEACTIVATING, INACTIVE, ACTIVE, ERRORPROCESSING),
    TransitionInfo(5, "shutdown", UNCONFIGURED, SHUTTINGDOWN),
    TransitionInfo(6, "shutdown", INACTIVE, SHUTTINGDOWN),
    TransitionInfo(7, "shutdown", ACTIVE, SHUTTINGDOWN),
    *_outcomes(50, SHUTTINGDOWN, FINALIZED, FINALIZED, ERRORPROCESSING),
    *_outcomes(60, ERRORPROCESSING, UNCONFIGURED, FINALIZED, FINALIZED),
)

# the shutdown transition to request from each primary state
SHUTDOWN_FROM = {UNCONFIGURED.label: 5, INACTIVE.label: 6, ACTIVE.label: 7}


class StateMachine:
    """One node's current state and the moves rcl_lifecycle allows from it."""

    def __init__(self) -> None:
        self.current = UNCONFIGURED

    @property
    def current_state(self) -> StateInfo:
        """The current state as (id, label), as rclpy's state machine gives it."""
        return self.current

    @property
    def available_states(self) -> tuple[StateInfo, ...]:
        """Every state of the machine."""
        return STATES

    @property
    def available_transitions(self) -> list[TransitionInfo]:
        """The transitions that start in the current state."""
        return [t for t in TRANSITIONS if t.start == self.current]

    @property
    def transition_graph(self) -> tuple[TransitionInfo, ...]:
        """Every transition of the machine."""
        return TRANSITIONS

    def transition_by_id(self, transition_id: int) -> TransitionInfo:
        """The transition ``transition_id`` from the current state.

        Raises:
            LifecycleTransitionError: no such transition starts in the current state.
        """
        return self._find("id", transition_id)

    def transition_by_label(self, label: str) -> TransitionInfo:
        """The transition called ``label`` from the current state.

        Raises:
            LifecycleTransitionError: no such transition starts in the current state.
        """
        return self._find("label", label)

    def _find(self, field: str, wanted: int | str) -> TransitionInfo:
        for transition in self.available_transitions:
            if getattr(transition, field) == wanted:
                return transition
        raise LifecycleTransitionError(
            f"No transition matching {wanted} found for current state {self.current.label}"
        )

    def take(self, transition: TransitionInfo) -> tuple[StateInfo, StateInfo]:
        """Move along ``transition`` (which must start here); return (start, goal)."""
        if transition.start != self.current:
            raise LifecycleTransitionError(
                f"Transition {transition.label} [{transition.id}] starts in "
                f"{transition.start.label}, not in the current state {self.current.label}"
            )
        self.current = transition.goal
        return transition.start, transition.goal
