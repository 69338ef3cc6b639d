"""StateMachine: a finite state machine of labelled states joined by outcome -> target transitions.

A target is another state's label, one of the machine's own outcomes, or None (the outcome of the
same name leaves the machine). The run loop holds ``_transition_lock`` except while a child executes,
so a preempt request lands either on the running child or before the next one starts.
"""

from __future__ import annotations

import threading
from typing import Any

from ninjemys.smach.container import Container
from ninjemys.smach.errors import (
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
    user_traceback,
)
from ninjemys.smach.log import is_shutdown, logdebug, logerr, loginfo, logwarn
from ninjemys.smach.state import State
from ninjemys.smach.userdata import Remapper, UserData

__all__ = ["StateMachine"]


class StateMachine(Container):
    """``with sm: StateMachine.add('LABEL', state, transitions={...}, remapping={...})``."""

    def __init__(self, outcomes: Any, input_keys: Any = (), output_keys: Any = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        self._transition_lock = threading.Lock()
        self._is_running = False
        self._initial_state_label: str | None = None
        self._current_label: str | None = None
        self._current_state: State | None = None
        self._current_transitions: dict[str, str | None] | None = None
        self._preempted_label: str | None = None
        self._preempted_state: State | None = None
        self._states: dict[str, State] = {}
        self._transitions: dict[str, dict[str, str | None]] = {}
        self._remappings: dict[str, dict[str, str]] = {}
        self._constants: dict[str, dict[str, Any]] = {}
        self._last_added_label: str | None = None
        self._connector_outcomes: list[str] = []

    def __getstate__(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items() if k != "_transition_lock"}

    def __setstate__(self, d: dict[str, Any]) -> None:
        self.__dict__ = d
        self._transition_lock = threading.Lock()

    # -- construction --
    @staticmethod
    def add(
        label: str,
        state: State,
        transitions: dict[str, str | None] | None = None,
        remapping: dict[str, str] | None = None,
        constants: dict[str, Any] | None = None,
    ) -> State:
        """Add ``state`` as ``label`` to the open machine; the first one added is the initial state.

        Outcomes without a transition map to None (they leave the machine under their own name).
        """
        self = StateMachine._currently_opened_container()
        logdebug(f"Adding state ({label}, {state}, {transitions})")
        if self._initial_state_label is None:
            self._initial_state_label = label
        transitions = dict(transitions or {})
        self.check_state_spec(label, state, transitions)
        if label in self._states:
            raise InvalidStateError(
                f'Attempting to add state with label "{label}" to state machine, but this label is already being used.'
            )
        for outcome in state.get_registered_outcomes():
            transitions.setdefault(outcome, None)
        self._states[label] = state
        self._transitions[label] = transitions
        self._remappings[label] = dict(remapping or {})
        self._constants[label] = dict(constants or {})
        if self._connector_outcomes and self._last_added_label is not None:
            for outcome in self._connector_outcomes:
                self._transitions[self._last_added_label][outcome] = label
            self._connector_outcomes = []
            self._last_added_label = None
        return state

    @staticmethod
    def add_auto(
        label: str,
        state: State,
        connector_outcomes: list[str],
        transitions: dict[str, str | None] | None = None,
        remapping: dict[str, str] | None = None,
        constants: dict[str, Any] | None = None,
    ) -> State:
        """Add ``state`` so that its ``connector_outcomes`` lead to whichever state is added next."""
        self = StateMachine._currently_opened_container()
        added = StateMachine.add(label, state, transitions, remapping, constants)
        registered = state.get_registered_outcomes()
        if not all(o in registered for o in connector_outcomes):
            raise InvalidStateError(
                f"Attempting to auto-connect states with outcomes {connector_outcomes}, but state "
                f"'{label}' only has registerd outcomes: {registered}"
            )
        self._last_added_label = label
        self._connector_outcomes = list(connector_outcomes)
        return added

    def check_state_spec(self, label: str, state: State, transitions: dict[str, str | None]) -> None:
        """Every outcome named in ``transitions`` must be one the state registered."""
        registered = state.get_registered_outcomes()
        for outcome in transitions:
            if outcome not in registered:
                raise InvalidTransitionError(
                    f"Specified outcome '{outcome}' on state '{label}', which only has available "
                    f"registered outcomes: {registered}"
                )

    def check_consistency(self) -> None:
        """Every target must be a state or a machine outcome, and there must be an initial state."""
        own_outcomes = self.get_registered_outcomes()
        available = set(self._states) | set(own_outcomes)
        errors = ""
        if self._initial_state_label is None:
            errors += "\n\tNo initial state set."
        elif self._initial_state_label not in self._states:
            errors += f"\n\tInitial state label: '{self._initial_state_label}' is not in the state machine."
        for label, transitions in self._transitions.items():
            targets = {t for t in transitions.values() if t}
            missing = targets - available
            if missing:
                errors += f"\n\tState '{label}' references unknown states: {sorted(missing)}"
            terminal = {o for o, t in transitions.items() if not t}
            unregistered = terminal - set(own_outcomes)
            if unregistered:
                errors += f"\n\tState '{label}' references unregistered outcomes: {sorted(unregistered)}"
        if errors:
            raise InvalidTransitionError(
                "State machine failed consistency check: "
                + errors
                + f"\n\n\tAvailable states: {sorted(available)}"
            )

    # -- running --
    def _set_current_state(self, label: str | None) -> None:
        self._current_label = label
        self._current_state = self._states[label] if label is not None else None
        self._current_transitions = self._transitions[label] if label is not None else None

    def execute(self, parent_ud: Any = None) -> str | None:
        """Run from the initial state until an outcome leaves the machine (None if it is inconsistent)."""
        with self._transition_lock:
            try:
                self.check_consistency()
            except (InvalidStateError, InvalidTransitionError):
                logerr("Container consistency check failed.")
                return None
            self._is_running = True
            self._preempted_label = None
            self._preempted_state = None
            self._set_current_state(self._initial_state_label)
            self._copy_input_keys(parent_ud, self.userdata)
            loginfo(
                f"State machine starting in initial state '{self._current_label}' with userdata: \n\t"
                f"{self.userdata.keys()}"
            )
            self.call_start_cbs()
            outcome: str | None = None
            try:
                while outcome is None and self._is_running and not is_shutdown():
                    outcome = self._update_once()
                self._copy_output_keys(self.userdata, parent_ud)
            finally:
                self._is_running = False
        return outcome

    def _update_once(self) -> str | None:
        """Run the current state once and follow its outcome (lock held on entry and exit)."""
        label = self._current_label
        if label not in self._states:
            raise InvalidStateError(
                f"State '{label}' does not exist. Available states are: {list(self._states)}"
            )
        state = self._states[label]
        if self.preempt_requested():
            loginfo("Preempt requested on state machine before executing the next state.")
            if self._preempted_state is not None and not self._preempted_state.preempt_requested():
                # the last state serviced the preempt: the machine's preempt is handled
                self._preempt_requested = False
                self._preempted_state = None
            else:
                if self._preempted_state is not None:
                    loginfo(
                        f"Last state '{self._preempted_label}' did not service preempt. Preempting next "
                        f"state '{label}' before executing..."
                    )
                self._preempt_current_state()
        self._transition_lock.release()
        try:
            for key, value in self._constants[label].items():
                self.userdata[key] = value
            view = Remapper(
                self.userdata,
                state.get_registered_input_keys(),
                state.get_registered_output_keys(),
                self._remappings[label],
            )
            outcome = state.execute(view)
        except InvalidUserCodeError:
            logerr(f"State '{label}' failed to execute.")
            raise
        except Exception:
            raise InvalidUserCodeError(
                f"Could not execute state '{label}' of type '{state}': " + user_traceback()
            ) from None  # its traceback is in the message (see errors.user_traceback)
        finally:
            self._transition_lock.acquire()
        registered = state.get_registered_outcomes()
        if outcome not in registered:
            raise InvalidTransitionError(
                f"Attempted to return outcome '{outcome}' from state '{label}' of type '{state}' which only "
                f"has registered outcomes: {registered}"
            )
        transitions = self._transitions[label]
        if outcome not in transitions:
            raise InvalidTransitionError(
                f"Outcome '{outcome}' of state '{label}' is not bound to any transition target. Bound "
                f"transitions include: {transitions}"
            )
        target = transitions[outcome]
        if target in self._states:
            self._set_current_state(target)
            loginfo(f"State machine transitioning '{label}':'{outcome}'-->'{target}'")
            self.call_transition_cbs()
            return None
        if self._preempt_requested and self._preempted_state is not None and not state.preempt_requested():
            self.service_preempt()
        if target not in self.get_registered_outcomes():
            target = outcome
        if target not in self.get_registered_outcomes():
            raise InvalidTransitionError(
                f"Outcome '{outcome}' of state '{label}' with transition target '{target}' is neither a "
                "registered state nor a registered container outcome."
            )
        self._set_current_state(None)
        loginfo(f"State machine terminating '{label}':'{outcome}':'{target}'")
        self.call_termination_cbs([label], target)
        return target

    def request_preempt(self) -> None:
        """Preempt the machine: the running child is asked to stop, and no further child starts."""
        with self._transition_lock:
            self._preempt_requested = True
            if self._current_state is not None:
                self._preempt_current_state()

    def _preempt_current_state(self) -> None:
        if self._preempted_state is self._current_state:
            return
        if self._preempted_state is not None:
            self._preempted_state.recall_preempt()
        self._preempted_state = self._current_state
        self._preempted_label = self._current_label
        try:
            if self._preempted_state is not None:
                self._preempted_state.request_preempt()
        except Exception:
            logerr(f"Failed to preempt contained state '{self._preempted_label}': {user_traceback()}")

    # -- introspection --
    def get_children(self) -> dict[str, State]:
        return self._states

    def __getitem__(self, key: str) -> State:
        if key not in self._states:
            logerr(
                f"Attempting to get state '{key}' from StateMachine container. The only available states "
                f"are: {list(self._states)}"
            )
            raise KeyError(key)
        return self._states[key]

    def set_initial_state(self, initial_states: list[str], userdata: UserData | None = None) -> None:
        logdebug(f"Setting initial states to {initial_states}")
        if len(initial_states) > 1:
            logwarn(
                "Attempting to set initial state to include more than one state, but the StateMachine "
                "container can only have one initial state. Taking the first one."
            )
        if initial_states:
            self._initial_state_label = initial_states[0]
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> list[str]:
        return [str(self._current_label)]

    def get_initial_states(self) -> list[str]:
        return [str(self._initial_state_label)]

    def get_internal_edges(self) -> list[tuple[str, str, str | None]]:
        return [
            (outcome, label, target)
            for label, transitions in self._transitions.items()
            for outcome, target in transitions.items()
        ]

    def is_running(self) -> bool:
        return self._is_running
