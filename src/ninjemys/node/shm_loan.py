"""Loaned messages: the publisher writes a big array straight into a shared-memory slot.

Why: over SHMROS an ordinary ``publish`` copies the message's bytes into a slot once (6 MB for a
1080p image, about 1 ms on this kind of machine); that copy is most of a large message's latency and
CPU. With a loan the user fills the array where the subscriber will read it, and ``publish`` writes
only the small fields around it and sends the slot notice (the names follow iceoryx's ``loan()`` and
ROS 2's ``LoanedMessage``)::

    with pub.loan(height * step, height=h, width=w, encoding="rgb8", step=step) as msg:
        camera.read_into(msg.data)  # a writable numpy uint8 array, in shared memory
        pub.publish(msg)

Rules, each there so a loan can never alias a message somebody still reads:

* the loan comes from the ring of one SHMROS subscriber of the topic; every other subscriber gets the
  same bytes as usual (another SHMROS one by a copy into its own ring, TCPROS/UNIXROS ones, rospy and
  recorders included, by the socket's own copy out of the slot, in-process ones a serialized copy);
* the slot stays busy while any view of the loaned array lives (published or not) and, once
  published, until the subscriber has released the message: leaving the ``with`` block detaches the
  array from the message (its field becomes empty), so the slot comes back at once unless the
  user kept the array itself; without ``with``, dropping the message returns it the same way (with
  ``intraprocess=True`` the message object itself may be an in-process subscriber's: it is left
  whole, and the slot waits for every holder to drop it);
* after ``publish`` the loan is the subscriber's to read: take a new loan for the next message
  (publishing the same loan again while the first is unread falls back to copying);
* no SHMROS subscriber, a message below the shared-memory threshold, every slot busy (a publisher
  with ``queue_size=None`` first waits up to ``shm_link.SLOT_WAIT`` for one, as its publish does), a loan larger
  than a slot or a full /dev/shm: the array is an ordinary heap buffer instead (``loan.shared`` is
  False) and ``publish`` works exactly as for any message. The array's initial contents are undefined
  in both cases (a slot holds an earlier message).

Only a variable-length ``uint8[]``/``char[]`` field can be loaned (images, point clouds, compressed
images: the traffic that is large); the field is found by itself when the type has just one.
"""

from __future__ import annotations

from ninjemys.errors import NinjemysError
from ninjemys.node import shm_link

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

    from ninjemys.node.topics import Publisher


class LoanError(NinjemysError):
    """A loan asked for a field that cannot be loaned, or a bad length or field value."""


class LoanedMessage:
    """A message whose big array was loaned (see the module docstring); a context manager whose
    ``with`` gives the message and whose end detaches the array, so its slot comes back."""

    __slots__ = ("msg", "field", "shared", "_detach")

    def __init__(self, msg: Any, field: str, shared: bool, detach: bool = True) -> None:
        self.msg = msg
        #: the loaned field's name
        self.field = field
        #: True when the array lives in a shared-memory slot, False for the heap fallback
        self.shared = shared
        self._detach = detach

    def __enter__(self) -> Any:
        return self.msg

    def __exit__(self, *exc: object) -> None:
        self.release()

    def release(self) -> None:
        """Detach the array from the message (its field becomes empty): the slot is free again as
        soon as no other view of the array lives and the subscriber released what was published.
        Not for a publisher with ``intraprocess=True``: its in-process subscribers may hold this
        very message object, which must stay whole (the slot then waits for them to drop it)."""
        if self._detach:
            setattr(self.msg, self.field, b"")

    def __repr__(self) -> str:
        where = "shared memory" if self.shared else "the heap"
        return f"<LoanedMessage {type(self.msg).__name__}.{self.field} in {where}>"


def loan_field(msg_class: Any, field: str | None) -> str:
    """The name of the field a loan fills: ``field`` checked, or the type's only ``uint8[]``."""
    candidates = [
        name
        for name, ftype in getattr(msg_class, "_fields", ())
        if ftype.is_array and ftype.array_len is None and ftype.base in ("uint8", "char")
    ]
    type_name = getattr(msg_class, "_type", repr(msg_class))
    if field is None:
        if len(candidates) != 1:
            found = ", ".join(candidates) or "none"
            raise LoanError(f"{type_name}: name the field to loan (uint8[] fields: {found})")
        return candidates[0]
    if field not in candidates:
        raise LoanError(
            f"{type_name}.{field}: only a uint8[]/char[] field can be loaned "
            f"(this type has: {', '.join(candidates) or 'none'})"
        )
    return field


def loan(publisher: Publisher, length: int, field: str | None, fields: dict[str, Any]) -> LoanedMessage:
    """Build the message for :meth:`ninjemys.node.topics.Publisher.loan` (see the module docstring)."""
    cls = publisher.data_class
    name = loan_field(cls, field)
    if not isinstance(length, int) or isinstance(length, bool) or length < 0:
        raise LoanError(f"{publisher.name}: loan length must be a byte count >= 0, got {length!r}")
    if name in fields:
        raise LoanError(f"{publisher.name}: {name} is the loaned array: fill it after the loan")
    try:
        msg = cls(**fields)
    except (TypeError, ValueError) as exc:
        raise LoanError(f"{publisher.name}: {exc}") from None
    array = _shared_array(publisher, length)
    shared = array is not None
    if array is None:
        import numpy

        array = numpy.empty(length, dtype=numpy.uint8)
    setattr(msg, name, array)
    return LoanedMessage(msg, name, shared, not publisher.intraprocess)


def _shared_array(publisher: Publisher, length: int) -> Any:
    """A slot's array from the first SHMROS subscriber's ring that has one free, or None."""
    if length < shm_link.THRESHOLD:
        return None  # it would travel inline: no slot to spend on it
    rings = [
        ring
        for conn in publisher._pub.connections
        if isinstance(conn, shm_link.ShmPubConnection) and not conn.closed
        for ring in (conn._ring(),)
        if ring is not None
    ]
    for ring in rings:
        array = ring.lend(length)
        if array is not None:
            return array
    if rings and publisher.queue_size is None:
        # synchronous, as its publish: the subscriber is most likely just behind (see put)
        return rings[0].lend(length, shm_link.SLOT_WAIT)
    return None
