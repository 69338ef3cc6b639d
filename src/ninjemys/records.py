"""Value semantics for small slotted classes: what ``@dataclass(slots=True)`` would give, without
importing ``dataclasses`` (it pulls ``inspect``, ``ast`` and ``dis``: ~10 ms of every node's and
tool's start-up)."""

from __future__ import annotations


class SlotRecord:
    """Compared and shown by the values of ``__slots__`` (mutable, so not hashable)."""

    __slots__: tuple[str, ...] = ()

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return all(getattr(self, name) == getattr(other, name) for name in self.__slots__)

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        inner = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__slots__)
        return f"{type(self).__name__}({inner})"
