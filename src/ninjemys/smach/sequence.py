"""Sequence: a StateMachine whose states are chained in the order added, through one connector outcome."""

from __future__ import annotations

from typing import Any

from ninjemys.smach.log import logerr
from ninjemys.smach.state import State
from ninjemys.smach.state_machine import StateMachine

__all__ = ["Sequence"]


class Sequence(StateMachine):
    """``Sequence(outcomes, connector_outcome)``: each added state's ``connector_outcome`` leads to the next."""

    def __init__(
        self, outcomes: Any, connector_outcome: str, input_keys: Any = (), output_keys: Any = ()
    ) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        self._last_added_seq_label: str | None = None
        self._connector_outcome = connector_outcome

    @staticmethod
    def add(  # type: ignore[override]
        label: str,
        state: State,
        transitions: dict[str, str | None] | None = None,
        remapping: dict[str, str] | None = None,
    ) -> State:
        """Add ``state`` after the previous one; an explicit transition for the connector outcome wins."""
        self = Sequence._currently_opened_container()
        previous = self._last_added_seq_label
        if previous is not None:
            if self._transitions[previous].get(self._connector_outcome) is None:
                self._transitions[previous][self._connector_outcome] = label
            try:
                self.check_state_spec(previous, self._states[previous], self._transitions[previous])
            except Exception:
                logerr("Attempting to construct smach state sequence failed.")
        self._last_added_seq_label = label
        return StateMachine.add(label, state, transitions, remapping)
