"""Iterator: run one contained state once per item, the item in userdata under ``it_label``."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from ninjemys.smach.container import Container
from ninjemys.smach.errors import InvalidUserCodeError, user_traceback
from ninjemys.smach.log import is_shutdown, logerr, loginfo, logwarn
from ninjemys.smach.state import State
from ninjemys.smach.userdata import UserData

__all__ = ["Iterator"]


class Iterator(Container):
    """Loop outcomes continue with the next item; break outcomes (or a preempt) end the loop early;
    running out of items gives ``exhausted_outcome``. ``final_outcome_map`` renames the last outcome."""

    def __init__(
        self,
        outcomes: list[str],
        input_keys: Any,
        output_keys: Any,
        it: Iterable[Any] | Callable[[], Iterable[Any]] = (),
        it_label: str = "it_data",
        exhausted_outcome: str = "exhausted",
    ) -> None:
        outcomes = list(outcomes)
        if exhausted_outcome not in outcomes:
            outcomes.append(exhausted_outcome)
        super().__init__(outcomes, input_keys, output_keys)
        self._items = it
        self._items_label = it_label
        self._is_running = False
        self._state_label = ""
        self._state: State | None = None
        self._loop_outcomes: list[str] = []
        self._break_outcomes: list[str] = []
        self._final_outcome_map: dict[str, str] = {}
        self._exhausted_outcome = exhausted_outcome

    @staticmethod
    def set_iteritems(it: Iterable[Any] | Callable[[], Iterable[Any]], it_label: str = "it_data") -> None:
        """The items (or a callable returning them, evaluated at each execution) of the open Iterator."""
        self = Iterator._currently_opened_container()
        self._items = it
        self._items_label = it_label

    @staticmethod
    def set_contained_state(
        label: str,
        state: State,
        loop_outcomes: list[str] | None = None,
        break_outcomes: list[str] | None = None,
        final_outcome_map: dict[str, str] | None = None,
    ) -> None:
        """The state to run per item; outcomes not listed as loop outcomes break (or the reverse)."""
        self = Iterator._currently_opened_container()
        self._state_label = label
        self._state = state
        loop_outcomes, break_outcomes = list(loop_outcomes or []), list(break_outcomes or [])
        if loop_outcomes and break_outcomes:
            logwarn(
                "Both loop_outcomes and break_outcomes were specified when constructing SMACH iterator container."
            )
        outcomes = state.get_registered_outcomes()
        if break_outcomes:
            self._break_outcomes = break_outcomes
            self._loop_outcomes = [o for o in outcomes if o not in break_outcomes]
        else:
            self._loop_outcomes = loop_outcomes
            self._break_outcomes = [o for o in outcomes if o not in loop_outcomes]
        self._final_outcome_map = dict(final_outcome_map or {})

    def execute(self, parent_ud: Any = None) -> str | None:
        if self._state is None:
            raise InvalidUserCodeError("Iterator has no contained state (call Iterator.set_contained_state)")
        self._is_running = True
        self._copy_input_keys(parent_ud, self.userdata)
        self.call_start_cbs()
        outcome: str | None = self._exhausted_outcome
        items = self._items() if callable(self._items) else self._items
        iterator = iter(items)
        while not is_shutdown():
            try:
                item = next(iterator)
            except StopIteration:
                outcome = self._exhausted_outcome
                break
            loginfo(f"Iterating {item} of {self._items}")
            self.userdata[self._items_label] = item
            try:
                outcome = self._state.execute(self.userdata)
            except InvalidUserCodeError:
                logerr(f"Could not execute Iterator state '{self._state_label}'")
                raise
            except Exception:
                raise InvalidUserCodeError(
                    f"Could not execute iterator state '{self._state_label}' of type '{self._state}': "
                    + user_traceback()
                ) from None  # its traceback is in the message (see errors.user_traceback)
            if (
                self._preempt_requested
                or outcome in self._break_outcomes
                or (self._loop_outcomes and outcome not in self._loop_outcomes)
            ):
                self._preempt_requested = False
                break
            self.call_transition_cbs()
        if outcome in self._final_outcome_map:
            outcome = self._final_outcome_map[outcome]
        self._copy_output_keys(self.userdata, parent_ud)
        self._is_running = False
        self.call_termination_cbs(self._state_label, outcome)
        return outcome

    def request_preempt(self) -> None:
        self._preempt_requested = True
        if self._is_running and self._state is not None:
            self._state.request_preempt()

    def get_children(self) -> dict[str, State]:
        return {self._state_label: self._state} if self._state is not None else {}

    def __getitem__(self, key: str) -> State:
        if key != self._state_label or self._state is None:
            logerr(
                f"Attempting to get state '{key}' from Iterator container. The only available state is "
                f"'{self._state_label}'."
            )
            raise KeyError(key)
        return self._state

    def get_initial_states(self) -> list[str]:
        return [self._state_label]

    def set_initial_state(self, initial_states: list[str], userdata: UserData | None = None) -> None:
        if len(initial_states) > 1:
            logwarn(
                "Attempting to set initial state to include more than one state, but Iterator container "
                "can only have one initial state."
            )
        if initial_states and initial_states[0] != self._state_label:
            logwarn(
                f"Attempting to set state '{initial_states[0]}' as initial state in Iterator container. "
                f"The only available state is '{self._state_label}'."
            )
            raise KeyError(initial_states[0])
        if userdata is not None:
            self.userdata.update(userdata)

    def get_active_states(self) -> list[str]:
        return [self._state_label] if self._is_running else []

    def get_internal_edges(self) -> list[tuple[str, str, str | None]]:
        edges: list[tuple[str, str, str | None]] = [
            (o, self._state_label, self._state_label) for o in self._loop_outcomes
        ]
        for outcome in self._break_outcomes:
            final = self._final_outcome_map.get(outcome, outcome)
            edges.append((outcome, self._state_label, None if final == outcome else final))
        return edges

    def check_consistency(self) -> None:
        """Nothing to check: any outcome of the contained state is either a loop or a break."""
