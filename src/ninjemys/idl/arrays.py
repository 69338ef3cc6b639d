"""Zero-copy values for deserialized arrays.

Representation choice (why): genpy turns a ``float32[]`` of 720 ranges into a tuple of 720 Python
floats and copies a 6 MB image into a fresh ``bytes``; both cost time proportional to the data on
every received message, even when the callback only looks at a few values or hands the buffer to numpy.
ninjemys instead keeps views over the received buffer:

* ``uint8[]`` / ``char[]`` (variable length) deserialize to a read-only ``memoryview`` (format ``B``)
  over the received bytes: ``len``, indexing, slicing, iteration, ``bytes(x)``, ``x == b"..."``,
  ``np.frombuffer(x, ...)`` and re-serialization all work without a copy. Fixed-size ``uint8[N]``
  stays ``bytes``, as in genpy.
* other variable-length numeric arrays deserialize to :class:`NumericArray`, an immutable sequence
  over a typed memoryview: elements are converted to Python numbers only when read; it compares equal
  to lists, tuples and other sequences with the same values; ``numpy.asarray(x)`` is a zero-copy view;
  re-serializing it writes the original bytes back without touching the elements. Fixed-size numeric
  arrays (covariances, ...) stay tuples, as in genpy.

Both keep the received buffer alive; the caller of ``deserialize_from`` must not mutate that buffer
afterwards (the node runtime hands over each received frame as immutable ``bytes``).
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Iterator, Sequence

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any


#: struct/memoryview format char -> numpy dtype string (little-endian wire layout)
NUMPY_DTYPES = {
    "b": "<i1",
    "B": "<u1",
    "h": "<i2",
    "H": "<u2",
    "i": "<i4",
    "I": "<u4",
    "q": "<i8",
    "Q": "<u8",
    "f": "<f4",
    "d": "<f8",
}
LITTLE_ENDIAN_HOST = sys.byteorder == "little"


class NumericArray(Sequence):
    """An immutable, lazily converted view of a received numeric array (see the module docstring)."""

    __slots__ = ("_raw", "_fmt", "_cast")

    def __init__(self, view: memoryview) -> None:
        """``view``: a typed memoryview (format ``f``, ``d``, ``i`` ...) over little-endian wire bytes.

        Generated code does not call this: it stores ``_raw`` (the wire bytes, a ``B`` memoryview) and
        ``_fmt`` directly, and the typed view is made on first use, so an array a callback never reads
        costs one slice.
        """
        self._raw = view.cast("B")
        self._fmt = view.format
        self._cast = view

    @property
    def _view(self) -> memoryview:
        try:
            return self._cast
        except AttributeError:
            # any struct format the message spec allows; typeshed's overloads take only literals
            typed = self._cast = self._raw.cast(self._fmt)  # type: ignore[call-overload]
            return typed

    @classmethod
    def from_wire(cls, raw: bytes | memoryview, fmt: str) -> NumericArray | tuple:
        """View ``raw`` (wire bytes) as elements of ``fmt``; a tuple on big-endian hosts."""
        if LITTLE_ENDIAN_HOST:
            return cls(memoryview(raw).cast("B").cast(fmt))  # type: ignore[call-overload]  # as in _view
        count = len(raw) // struct.calcsize(fmt)
        return struct.unpack(f"<{count}{fmt}", raw)

    @property
    def format(self) -> str:
        """The struct format char of the elements (``f`` for float32, ...)."""
        return self._fmt

    def raw_bytes(self) -> memoryview:
        """The elements in ROS wire layout (little-endian), without copying."""
        return self._raw

    def __len__(self) -> int:
        return len(self._view)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return tuple(self._view[index])
        return self._view[index]

    def __iter__(self) -> Iterator[Any]:
        return iter(self._view)

    def __reversed__(self) -> Iterator[Any]:
        return reversed(self.tolist())

    def __contains__(self, value: object) -> bool:
        return value in self.tolist()

    def tolist(self) -> list[Any]:
        return self._view.tolist()

    def __eq__(self, other: object) -> bool:
        if isinstance(other, NumericArray):
            return self.tolist() == other.tolist()
        if isinstance(other, list):
            return self.tolist() == other
        if isinstance(other, tuple):
            return tuple(self.tolist()) == other
        if isinstance(other, Sequence) and not isinstance(other, str | bytes):
            return self.tolist() == list(other)
        if type(other).__module__ == "numpy" and hasattr(other, "tolist"):
            return self.tolist() == other.tolist()
        return NotImplemented

    def __ne__(self, other: object) -> bool:
        result = self.__eq__(other)
        return result if result is NotImplemented else not result

    __hash__ = None  # type: ignore[assignment]

    def __add__(self, other: Any) -> Any:
        if isinstance(other, list):
            return self.tolist() + other
        return tuple(self.tolist()) + tuple(other)

    def __radd__(self, other: Any) -> Any:
        if isinstance(other, list):
            return other + self.tolist()
        return tuple(other) + tuple(self.tolist())

    def __repr__(self) -> str:
        return repr(tuple(self.tolist()))

    def __array__(self, dtype: Any = None, copy: Any = None) -> Any:
        import numpy

        arr = numpy.frombuffer(self._raw, dtype=NUMPY_DTYPES[self._fmt])
        if dtype is not None:
            arr = arr.astype(dtype)
        return arr

    def __reduce__(self) -> tuple[Any, ...]:
        return (tuple, (tuple(self.tolist()),))

    def __copy__(self) -> NumericArray:
        return self

    def __deepcopy__(self, memo: dict) -> list[Any]:
        return self.tolist()


class _NoSlotsHere:
    """Makes ``__slots__`` unreadable on :class:`NumericArray` (its layout is unchanged).

    genpy gives a variable-length numeric array as a tuple, which has no ``__slots__``; code that walks
    a message through ``type(value).__slots__`` (rosbag_to_csv and its copies) recurses into whatever
    has them and writes ``str(value)`` for the rest. Our array's own slots (``_raw``, ``_fmt``, ...)
    would be walked instead of the values being written, so reading the name fails here as on a tuple.
    """

    def __get__(self, obj: object, owner: type | None = None) -> Any:
        raise AttributeError("__slots__")


NumericArray.__slots__ = _NoSlotsHere()  # type: ignore[assignment]
