"""States: the unit of work (``execute(userdata) -> outcome``), and the interface declarations."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

__all__ = ["CBInterface", "CBState", "State", "cb_interface", "has_smach_interface"]


class State:
    """A smach state: declares its outcomes and the userdata keys it reads and writes.

    Containers check these declarations when states are added and at run time (the userdata a state
    sees is a :class:`~ninjemys.smach.userdata.Remapper` that only lets declared keys through).
    """

    def __init__(
        self,
        outcomes: Iterable[str] = (),
        input_keys: Iterable[str] = (),
        output_keys: Iterable[str] = (),
        io_keys: Iterable[str] = (),
    ) -> None:
        io = list(io_keys)
        self._outcomes: set[str] = set(outcomes)
        self._input_keys: set[str] = set(input_keys) | set(io)
        self._output_keys: set[str] = set(output_keys) | set(io)
        self._preempt_requested = False

    def execute(self, ud: Any) -> str | None:
        """Do the work and return one of the registered outcomes. Subclasses override this."""
        raise NotImplementedError(f"{type(self).__name__}.execute() is not overridden")

    def register_outcomes(self, new_outcomes: Iterable[str]) -> None:
        self._outcomes |= set(new_outcomes)

    def get_registered_outcomes(self) -> tuple[str, ...]:
        return tuple(self._outcomes)

    def register_io_keys(self, keys: Iterable[str]) -> None:
        keys = list(keys)
        self._input_keys |= set(keys)
        self._output_keys |= set(keys)

    def register_input_keys(self, keys: Iterable[str]) -> None:
        self._input_keys |= set(keys)

    def get_registered_input_keys(self) -> tuple[str, ...]:
        return tuple(self._input_keys)

    def register_output_keys(self, keys: Iterable[str]) -> None:
        self._output_keys |= set(keys)

    def get_registered_output_keys(self) -> tuple[str, ...]:
        return tuple(self._output_keys)

    def request_preempt(self) -> None:
        """Ask the state to stop early; a cooperative state checks :meth:`preempt_requested`."""
        self._preempt_requested = True

    def service_preempt(self) -> None:
        """The state acknowledges the preempt (it stopped because of it)."""
        self._preempt_requested = False

    def recall_preempt(self) -> None:
        """Withdraw an unserviced preempt request."""
        self._preempt_requested = False

    def preempt_requested(self) -> bool:
        return self._preempt_requested


def has_smach_interface(obj: object) -> bool:
    """True if ``obj`` declares outcomes and userdata keys (a State or a CBInterface)."""
    return all(
        hasattr(obj, name)
        for name in ("get_registered_input_keys", "get_registered_output_keys", "get_registered_outcomes")
    )


class CBInterface:
    """A callback that carries its smach interface: the outcomes it may return and keys it touches.

    States that take user callbacks (CBState, SimpleActionState's result_cb, ...) read these and
    register them on themselves, so the container's checks know about them.
    """

    def __init__(
        self,
        cb: Callable[..., Any],
        outcomes: Iterable[str] | None = None,
        input_keys: Iterable[str] | None = None,
        output_keys: Iterable[str] | None = None,
        io_keys: Iterable[str] | None = None,
    ) -> None:
        # as in smach, io_keys are accepted but not added to either set
        self._input_keys = set(input_keys or ())
        self._output_keys = set(output_keys or ())
        self._outcomes = list(outcomes or ())
        self._cb = cb
        self.__name__ = getattr(cb, "__name__", type(cb).__name__)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self._cb(*args, **kwargs)

    def get_registered_input_keys(self) -> tuple[str, ...]:
        return tuple(self._input_keys)

    def get_registered_output_keys(self) -> tuple[str, ...]:
        return tuple(self._output_keys)

    def get_registered_outcomes(self) -> tuple[str, ...]:
        return tuple(self._outcomes)


class cb_interface:  # noqa: N801 - smach's decorator name
    """Decorator: ``@smach.cb_interface(outcomes=[...], input_keys=[...], output_keys=[...])``."""

    def __init__(
        self,
        outcomes: Iterable[str] | None = None,
        input_keys: Iterable[str] | None = None,
        output_keys: Iterable[str] | None = None,
    ) -> None:
        self._outcomes = list(outcomes or ())
        self._input_keys = list(input_keys or ())
        self._output_keys = list(output_keys or ())

    def __call__(self, cb: Callable[..., Any]) -> CBInterface:
        return CBInterface(cb, self._outcomes, self._input_keys, self._output_keys)


class CBState(State):
    """A state made from one function ``cb(ud, *cb_args, **cb_kwargs) -> outcome``.

    A function decorated with :class:`cb_interface` brings its outcomes and keys along.
    """

    def __init__(
        self,
        cb: Callable[..., Any],
        cb_args: Iterable[Any] = (),
        cb_kwargs: dict[str, Any] | None = None,
        outcomes: Iterable[str] = (),
        input_keys: Iterable[str] = (),
        output_keys: Iterable[str] = (),
        io_keys: Iterable[str] = (),
    ) -> None:
        super().__init__(outcomes, input_keys, output_keys, io_keys)
        self._cb = cb
        self._cb_args = list(cb_args)
        self._cb_kwargs = dict(cb_kwargs or {})
        if has_smach_interface(cb):
            self.register_input_keys(cb.get_registered_input_keys())  # type: ignore[attr-defined]
            self.register_output_keys(cb.get_registered_output_keys())  # type: ignore[attr-defined]
            self.register_outcomes(cb.get_registered_outcomes())  # type: ignore[attr-defined]

    def execute(self, ud: Any) -> str | None:
        return self._cb(ud, *self._cb_args, **self._cb_kwargs)
