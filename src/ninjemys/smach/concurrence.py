"""Concurrence: run every child at once in its own thread and join them; the outcome comes from
``outcome_cb``, else the best-satisfied entry of ``outcome_map``, else ``default_outcome``.

``child_termination_cb(outcomes)`` runs each time a child finishes; returning True preempts the
children still running (a list of labels preempts just those). One condition variable carries
every wake-up (a child finished, a preempt arrived, a child raised), so nothing polls.
"""

from __future__ import annotations

import copy
import threading
from collections.abc import Callable
from typing import Any

from ninjemys.smach.container import Container
from ninjemys.smach.errors import (
    InvalidStateError,
    InvalidTransitionError,
    InvalidUserCodeError,
    user_traceback,
)
from ninjemys.smach.log import logdebug, logerr, loginfo, logwarn
from ninjemys.smach.state import State
from ninjemys.smach.userdata import Remapper, UserData

__all__ = ["Concurrence"]


class Concurrence(Container):
    """``Concurrence(outcomes, default_outcome, outcome_map={...}, outcome_cb=..., child_termination_cb=...)``."""

    def __init__(
        self,
        outcomes: Any,
        default_outcome: str,
        input_keys: Any = (),
        output_keys: Any = (),
        outcome_map: dict[str, dict[str, str]] | None = None,
        outcome_cb: Callable[[dict[str, str | None]], str | None] | None = None,
        child_termination_cb: Callable[[dict[str, str | None]], Any] | None = None,
    ) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        outcome_map = dict(outcome_map or {})
        if not (default_outcome or outcome_map or outcome_cb):
            raise InvalidStateError("Concurrence requires an outcome policy")
        errors = ""
        if not isinstance(default_outcome, str):
            errors += f"\n\tDefault outcome '{default_outcome}' does not appear to be a string."
        if default_outcome not in self._outcomes:
            errors += f"\n\tDefault outcome '{default_outcome}' is unregistered."
        for outcome in outcome_map:
            if outcome not in self._outcomes:
                errors += f"\n\tUnregistered outcome '{outcome}' in and_outcome_map."
        if outcome_cb is not None and not callable(outcome_cb):
            errors += f"\n\tOutcome callback '{outcome_cb}' is not callable."
        if child_termination_cb is not None and not callable(child_termination_cb):
            errors += f"\n\tChild termination callback '{child_termination_cb}' is not callable."
        if errors:
            raise InvalidStateError(f"Errors specifying outcome policy of concurrence: {errors}")
        self._default_outcome = default_outcome
        self._outcome_map = outcome_map
        self._outcome_cb = outcome_cb
        self._child_termination_cb = child_termination_cb
        self._states: dict[str, State] = {}
        self._remappings: dict[str, dict[str, str]] = {}
        self._threads: dict[str, threading.Thread] = {}
        self._child_outcomes: dict[str, str | None] = {}
        self._errors: list[BaseException] = []
        self._cond = threading.Condition()
        self._stop_others: bool | list[str] = False

    @staticmethod
    def add(label: str, state: State, remapping: dict[str, str] | None = None) -> State:
        """Add a child; the concurrence ends only once every child has ended."""
        self = Concurrence._currently_opened_container()
        self._states[label] = state
        self._remappings[label] = dict(remapping or {})
        return state

    def execute(self, parent_ud: Any = None) -> str | None:
        if not self._states:
            raise InvalidStateError("No states was added to concurrence")
        self._child_outcomes = dict.fromkeys(self._states)
        self._errors = []
        self._stop_others = False
        self._copy_input_keys(parent_ud, self.userdata)
        loginfo(f"Concurrence starting with userdata: \n\t{self.userdata.keys()}")
        self.call_start_cbs()
        self._threads = {
            label: threading.Thread(
                name=f"concurrent_split:{label}", target=self._run_child, args=(label,), daemon=True
            )
            for label in self._states
        }
        for thread in self._threads.values():
            thread.start()
        with self._cond:
            self._cond.wait_for(self._should_stop_others)
            stop = self._stop_others
        logdebug("SMACH Concurrence preempting running states.")
        targets = stop if isinstance(stop, list) else list(self._states)
        for label in targets:
            if self._child_outcomes.get(label) is None and label in self._states:
                self._states[label].request_preempt()
        for thread in self._threads.values():
            thread.join()
        if self._errors:
            self._errors = []
            raise InvalidStateError("A concurrent state raised an exception during execution.")
        if self.preempt_requested():
            serviced = True
            for label, state in self._states.items():
                if state.preempt_requested():
                    serviced = False
                    logwarn(f"State '{label}' in concurrence did not service preempt.")
                    state.recall_preempt()
            if serviced:
                loginfo("Concurrence serviced preempt.")
                self.service_preempt()
                return self._finish("preempted", parent_ud)
        loginfo(f"Concurrent Outcomes: {self._child_outcomes}")
        return self._finish(self._choose_outcome(), parent_ud)

    def _should_stop_others(self) -> bool:
        return bool(
            self._stop_others
            or self._errors
            or self._preempt_requested
            or all(o is not None for o in self._child_outcomes.values())
        )

    def _finish(self, outcome: str, parent_ud: Any) -> str:
        self._threads = {}
        self._child_outcomes = {}
        self.call_termination_cbs(list(self._states), outcome)
        self._copy_output_keys(self.userdata, parent_ud)
        return outcome

    def _choose_outcome(self) -> str:
        outcome = self._default_outcome
        best = 0
        for container_outcome, wanted in self._outcome_map.items():
            if all(self._child_outcomes.get(label) == o for label, o in wanted.items()):
                if len(wanted) > best:
                    outcome, best = container_outcome, len(wanted)
                else:
                    logdebug(f"Skipping mapped outcome '{container_outcome}' with fewer constraints.")
        if self._outcome_cb is not None:
            try:
                chosen = self._outcome_cb(copy.copy(self._child_outcomes))
            except Exception:
                raise InvalidUserCodeError(
                    f"Could not execute outcome callback '{self._outcome_cb}': " + user_traceback()
                ) from None  # its traceback is in the message (see errors.user_traceback)
            if chosen and isinstance(chosen, str):
                outcome = chosen
            elif chosen:
                logerr(
                    f"Outcome callback returned a non-string '{chosen}', using default outcome "
                    f"'{self._default_outcome}'"
                )
            else:
                logwarn(f"Outcome callback returned None, using outcome '{outcome}'")
        return outcome

    def _run_child(self, label: str) -> None:
        state = self._states[label]
        self.call_transition_cbs()
        try:
            outcome = state.execute(
                Remapper(
                    self.userdata,
                    state.get_registered_input_keys(),
                    state.get_registered_output_keys(),
                    self._remappings[label],
                )
            )
        except Exception as exc:
            logerr(f"Could not execute child state '{label}': " + user_traceback())
            with self._cond:
                self._errors.append(exc)
                self._cond.notify_all()
            return
        if outcome is None:
            logerr(f"Concurrent state '{label}' returned no outcome on termination.")
            with self._cond:
                self._errors.append(
                    InvalidStateError(f"Concurrent state '{label}' returned no outcome on termination.")
                )
                self._cond.notify_all()
            return
        loginfo(f"Concurrent state '{label}' returned outcome '{outcome}' on termination.")
        with self._cond:
            self._child_outcomes[label] = outcome
            self.call_transition_cbs()
            if self._child_termination_cb is not None:
                try:
                    stop = self._child_termination_cb(dict(self._child_outcomes))
                except Exception:
                    logerr("Could not execute child termination callback: " + user_traceback())
                    self._errors.append(InvalidUserCodeError("child termination callback raised"))
                    stop = False
                if stop:
                    self._stop_others = list(stop) if isinstance(stop, list | tuple) else True
            self._cond.notify_all()

    def request_preempt(self) -> None:
        """Preempt the concurrence: every running child is asked to stop."""
        with self._cond:
            super().request_preempt()
            self._cond.notify_all()

    # -- introspection --
    def get_children(self) -> dict[str, State]:
        return self._states

    def __getitem__(self, key: str) -> State:
        return self._states[key]

    def get_initial_states(self) -> list[str]:
        return list(self._states)

    def set_initial_state(self, initial_states: list[str], userdata: UserData | None = None) -> None:
        if initial_states and len(initial_states) < len(self._states):
            logwarn(
                "Attempting to set initial states in Concurrence container, but Concurrence children are "
                "always all executed initially, ignoring call."
            )
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> list[str]:
        return [label for label, outcome in self._child_outcomes.items() if outcome is None]

    def get_internal_edges(self) -> list[tuple[str, str, str | None]]:
        return [
            (child_outcome, label, container_outcome)
            for container_outcome, wanted in self._outcome_map.items()
            for label, child_outcome in wanted.items()
        ]

    def check_consistency(self) -> None:
        for wanted in self._outcome_map.values():
            for label, outcome in wanted.items():
                if label not in self._states:
                    raise InvalidTransitionError(
                        f"Outcome map in SMACH Concurrence references a state '{label}' that is not in the "
                        f"concurrence (children: {list(self._states)})"
                    )
                registered = self._states[label].get_registered_outcomes()
                if outcome not in registered:
                    raise InvalidTransitionError(
                        "Outcome map in SMACH Concurrence references a state outcome that does not exist. "
                        f"Requested state outcome: '{outcome}', but state '{label}' only has outcomes {registered}"
                    )
