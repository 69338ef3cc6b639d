"""The shared part of the ROS states: user callbacks that declare their own smach interface."""

from __future__ import annotations

from typing import Any

import smach


def interface_of(
    state: smach.State, cb: Any, input_keys: Any, output_keys: Any, outcomes: Any = None
) -> tuple[list[str], list[str]]:
    """Register ``cb``'s declared keys (and outcomes) on ``state``; return the keys its Remapper allows.

    A callback without a smach interface sees the state's ``input_keys``/``output_keys``.
    """
    if cb is not None and not callable(cb):
        raise smach.InvalidStateError(
            f"Callback object given to {type(state).__name__} that IS NOT a function object"
        )
    if smach.has_smach_interface(cb):
        ins, outs = list(cb.get_registered_input_keys()), list(cb.get_registered_output_keys())
        state.register_input_keys(ins)
        state.register_output_keys(outs)
        if outcomes is not None:
            state.register_outcomes(cb.get_registered_outcomes())
        return ins, outs
    return list(input_keys), list(output_keys)
