"""The container base: the ``with sm:`` construction stack and the start/transition/termination callbacks.

``StateMachine.add`` and friends are static methods that add to whichever container is open, so
construction code reads like a declaration. The stack is process-wide (as in smach) and guarded by a
reentrant lock, so two threads cannot interleave their constructions.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, ClassVar, TypeVar

from ninjemys.smach.errors import (
    InvalidConstructionError,
    InvalidStateError,
    InvalidTransitionError,
    user_traceback,
)
from ninjemys.smach.log import logerr, logwarn
from ninjemys.smach.state import State
from ninjemys.smach.userdata import UserData

__all__ = ["Container"]

C = TypeVar("C", bound="Container")


class Container(State):
    """A state made of states. Subclasses say how children run and how the outcome is chosen."""

    _construction_stack: ClassVar[list[Container]] = []
    _construction_lock: ClassVar[threading.RLock] = threading.RLock()
    _context_kwargs: ClassVar[dict[str, Any]] = {}

    def __init__(self, outcomes: Any = (), input_keys: Any = (), output_keys: Any = ()) -> None:
        super().__init__(outcomes, input_keys, output_keys)
        self.userdata = UserData()
        self._start_cbs: list[tuple[Callable[..., Any], list[Any]]] = []
        self._transition_cbs: list[tuple[Callable[..., Any], list[Any]]] = []
        self._termination_cbs: list[tuple[Callable[..., Any], list[Any]]] = []

    # -- what each container type provides (introspection reads these) --
    def __getitem__(self, key: str) -> State:
        raise NotImplementedError

    def get_children(self) -> dict[str, State]:
        raise NotImplementedError

    def set_initial_state(self, initial_states: list[str], userdata: UserData | None = None) -> None:
        raise NotImplementedError

    def get_initial_states(self) -> list[str]:
        raise NotImplementedError

    def get_active_states(self) -> list[str]:
        raise NotImplementedError

    def get_internal_edges(self) -> list[tuple[str, str, str | None]]:
        """``(outcome, from_label, to_label)`` for every edge inside this container."""
        raise NotImplementedError

    def check_consistency(self) -> None:
        raise NotImplementedError

    # -- userdata in and out --
    def _copy_input_keys(self, parent_ud: Any, ud: Any) -> None:
        if parent_ud is None:
            return
        for key in self.get_registered_input_keys():
            try:
                ud[key] = parent_ud[key]
            except KeyError:
                logwarn(f"Attempting to copy input key '{key}', but this key does not exist.")

    def _copy_output_keys(self, ud: Any, parent_ud: Any) -> None:
        if parent_ud is None:
            return
        for key in self.get_registered_output_keys():
            try:
                parent_ud[key] = ud[key]
            except KeyError:
                logwarn(f"Attempting to copy output key '{key}', but this key does not exist.")

    # -- callbacks (the introspection server hooks in here) --
    def register_start_cb(self, start_cb: Callable[..., Any], cb_args: list[Any] | None = None) -> None:
        """``start_cb(userdata, initial_states, *cb_args)`` when the container starts."""
        self._start_cbs.append((start_cb, list(cb_args or [])))

    def register_transition_cb(
        self, transition_cb: Callable[..., Any], cb_args: list[Any] | None = None
    ) -> None:
        """``transition_cb(userdata, active_states, *cb_args)`` after every change of active states."""
        self._transition_cbs.append((transition_cb, list(cb_args or [])))

    def register_termination_cb(
        self, termination_cb: Callable[..., Any], cb_args: list[Any] | None = None
    ) -> None:
        """``termination_cb(userdata, terminal_states, container_outcome, *cb_args)`` when it ends."""
        self._termination_cbs.append((termination_cb, list(cb_args or [])))

    def call_start_cbs(self) -> None:
        try:
            for cb, args in self._start_cbs:
                cb(self.userdata, self.get_initial_states(), *args)
        except Exception:
            logerr("Could not execute start callback: " + user_traceback())

    def call_transition_cbs(self) -> None:
        try:
            for cb, args in self._transition_cbs:
                cb(self.userdata, self.get_active_states(), *args)
        except Exception:
            logerr("Could not execute transition callback: " + user_traceback())

    def call_termination_cbs(self, terminal_states: Any, outcome: str | None) -> None:
        try:
            for cb, args in self._termination_cbs:
                cb(self.userdata, terminal_states, outcome, *args)
        except Exception:
            logerr("Could not execute termination callback: " + user_traceback())

    # -- construction --
    def __enter__(self: C) -> C:
        self.open()
        return self

    def __exit__(self, exc_type: Any, exc_val: Any, exc_tb: Any) -> bool | None:
        if exc_type is None:
            self.close()
            return None
        if exc_type not in (InvalidStateError, InvalidTransitionError):
            logerr("Error raised during SMACH container construction: \n" + user_traceback(exc_val))
        # the exception propagates, but the container must not stay on the stack
        if Container._construction_stack and Container._construction_stack[-1] is self:
            Container._construction_stack.pop()
            Container._construction_lock.release()
        return None

    @contextmanager
    def opened(self: C, **kwargs: Any) -> Iterator[C]:
        """``with sm.opened(): ...`` (the same as ``with sm:``, with construction kwargs)."""
        self.open()
        previous = Container._context_kwargs
        Container._context_kwargs = kwargs
        try:
            yield self
        finally:
            Container._context_kwargs = previous
            self.close()

    def open(self) -> None:
        """Push this container on the construction stack (``add`` calls go to it)."""
        Container._construction_lock.acquire()
        Container._construction_stack.append(self)

    def close(self) -> None:
        """Pop this container and check it; an inconsistent machine is logged, not raised, as smach does."""
        if Container._construction_stack and Container._construction_stack[-1] is not self:
            raise InvalidStateError("Attempting to close a container that is not currently open.")
        Container._construction_stack.pop()
        Container._construction_lock.release()
        try:
            self.check_consistency()
        except (InvalidStateError, InvalidTransitionError):
            logerr("Container consistency check failed.")

    def is_opened(self) -> bool:
        return bool(Container._construction_stack) and Container._construction_stack[-1] is self

    def assert_opened(self, msg: str = "") -> None:
        if not self.is_opened():
            raise InvalidConstructionError(msg)

    @staticmethod
    def _any_containers_opened() -> bool:
        return bool(Container._construction_stack)

    @classmethod
    def _currently_opened_container(cls: type[C]) -> C:
        if not Container._construction_stack:
            raise InvalidStateError(
                "Attempting to access the currently opened container, but no container is opened."
            )
        opened = Container._construction_stack[-1]
        if not isinstance(opened, cls):
            raise InvalidStateError(
                f"Attempting to call a {cls} construction method without having opened a {cls}."
            )
        return opened
