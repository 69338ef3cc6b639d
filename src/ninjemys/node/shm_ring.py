"""A ring of shared-memory slots for one publisher->subscriber connection (``SHMROS``).

Why a ring per connection: each side writes only its own words, so no atomic instructions or
cross-process locks are needed (Python has neither). The publisher writes a slot's bytes and then
its *generation*; the subscriber writes the slot's *released* word (equal to the generation) once
the last view of that message is gone. A slot is free for the publisher iff released == generation.

Layout (little-endian, in a ``/dev/shm`` file)::

    0   magic  b"NJSHMv1\\0"
    8   u32 slots, u32 0, u64 slot_size
    24  per slot: u64 generation (publisher), u64 released (subscriber)
    DATA (page aligned): slots * slot_size bytes

Lifetime: segments are plain files opened with ``os.open`` and mapped with ``mmap`` (never
``multiprocessing.shared_memory``, whose resource tracker unlinks a segment the creating process
still shares, cpython#82300). The name carries the creator's pid; the subscriber unlinks the name
right after mapping it (open-then-unlink), the publisher unlinks it (again) when the connection
ends, and :func:`reap_stale` removes names of dead creators at start-up, so a SIGKILL at any point
leaves nothing behind for long. The mapping itself lives as long as a view into it does, so a view
a user keeps can never outlive its memory.
"""

from __future__ import annotations

import itertools
import mmap
import os
import struct
import sys
import threading
import time

from ninjemys.errors import NinjemysError

TYPE_CHECKING = False
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any

SHM_DIR = "/dev/shm"
PREFIX = "ninjemys-shm-"
MAGIC = b"NJSHMv1\0"
_HEAD = struct.Struct("<8sIIQ")
_WORD = struct.Struct("<Q")
_CTL = 24  # offset of the per-slot control words
#: the notice a publisher sends instead of the payload: tag 1, slot, generation, offset of the
#: payload in the slot (0, except for a loaned message: see :meth:`WriterRing.lend`), length
NOTICE = struct.Struct("<BIQQQ")
NOTICE_TAG, INLINE_TAG = 1, 0
#: the frame that names the ring, sent once before the first notice: tag 2, then the segment name
RING_TAG = 2

#: madvise(2) advice (Linux 5.14+; Python 3.11's mmap module does not name it)
_MADV_POPULATE_WRITE = getattr(mmap, "MADV_POPULATE_WRITE", 23)
#: how often a waiting publisher looks for a released slot (seconds)
_POLL = 100e-6
#: where a loaned array starts in its slot: the message's fields before the array (header, sizes,
#: encoding, the array's length) are written just in front of it at publish time, and the array
#: itself is page aligned (numpy and image libraries like that)
LOAN_OFFSET = 4096

_names = itertools.count(1)
_reaped = False


class ShmError(NinjemysError):
    """A segment could not be created, opened, or holds a layout we do not accept."""


def available() -> bool:
    """Shared memory between processes of this host: Linux with a ``/dev/shm`` directory."""
    return sys.platform.startswith("linux") and os.path.isdir(SHM_DIR)


def _data_offset(slots: int) -> int:
    ctl_end = _CTL + 16 * slots
    return (ctl_end + mmap.PAGESIZE - 1) // mmap.PAGESIZE * mmap.PAGESIZE


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def reap_stale() -> list[str]:
    """Unlink segments whose creating process is gone (a publisher SIGKILLed before its subscriber
    mapped the segment); returns the names removed. Done once per process, on the first ring."""
    removed: list[str] = []
    try:
        names = os.listdir(SHM_DIR)
    except OSError:
        return removed
    for name in names:
        if not name.startswith(PREFIX):
            continue
        try:
            pid = int(name[len(PREFIX) :].split("-", 1)[0])
        except ValueError:
            continue
        if pid != os.getpid() and not _pid_alive(pid):
            try:
                os.unlink(os.path.join(SHM_DIR, name))
                removed.append(name)
            except OSError:
                pass
    return removed


class WriterRing:
    """The publisher's side: picks a free slot, copies a payload in, stamps its generation."""

    def __init__(self, slots: int, slot_size: int) -> None:
        global _reaped
        if not _reaped:
            _reaped = True
            reap_stale()
        self.slots, self.slot_size = slots, slot_size
        self._data = _data_offset(slots)
        self.name = f"{PREFIX}{os.getpid()}-{next(_names)}-{os.urandom(4).hex()}"
        self.path = os.path.join(SHM_DIR, self.name)
        size = self._data + slots * slot_size
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o600)
        except OSError as exc:
            raise ShmError(f"cannot create {self.path}: {exc}") from None
        try:
            os.ftruncate(fd, size)
            self._mm = mmap.mmap(fd, size)
        except OSError as exc:
            os.close(fd)
            self.unlink()
            raise ShmError(f"cannot map {self.path}: {exc}") from None
        self._fd: int | None = fd  # kept for posix_fallocate as slots grow
        self._mm[: _HEAD.size] = _HEAD.pack(MAGIC, slots, 0, slot_size)
        self._gen = [0] * slots  # what we stamped
        #: slots loaned to the user (see lend): busy until the last view of the loan is gone
        self._lent = [False] * slots
        self._lease_types: dict[int, Any] = {}  # ctypes array types by size
        self._address = 0  # where the mapping starts in this process (found on the first loan)
        self._reclaimed = [0] * slots  # notices dropped before sending (queue_size)
        self._reserved = [0] * slots  # bytes of each slot backed by tmpfs pages (no SIGBUS)
        self._counter = 0
        self._patient = True  # False after a wait for a slot timed out (see put)
        self._lock = threading.Lock()
        self.closed = False

    def _free(self, slot: int) -> bool:
        if self._lent[slot]:
            return False
        gen = self._gen[slot]
        if gen == 0 or self._reclaimed[slot] == gen:
            return True
        return _WORD.unpack_from(self._mm, _CTL + 16 * slot + 8)[0] == gen

    def _free_slot(self) -> int | None:
        """The lowest free slot (a steady stream keeps reusing the same warm pages), or None."""
        for slot in range(self.slots):
            if self._free(slot):
                return slot
        return None

    def put(self, parts: list, length: int, wait: float = 0.0) -> bytes | None:
        """Copy ``parts`` (``length`` bytes) into a free slot; the notice frame (length prefix
        included) to send, or None when the payload does not fit or every slot is still held by the
        subscriber after ``wait`` seconds (the caller then sends the message inline). A synchronous
        publisher waits a little: its subscriber is merely behind, and the ring is the fast path."""
        if length > self.slot_size:
            return None
        return self._with_free_slot(wait, lambda slot: self._fill(slot, parts, length))

    def _with_free_slot(self, wait: float, take: Callable[[int], Any]) -> Any:
        """``take(slot)`` under the lock for the first free slot, waiting up to ``wait`` seconds for
        one; None when the ring is closed or no slot came free."""
        deadline = 0.0
        while True:
            with self._lock:
                if self.closed:
                    return None
                slot = self._free_slot()
                if slot is not None:
                    if not deadline:
                        self._patient = True  # slots come free again: worth waiting next time
                    return take(slot)
            if not wait or not self._patient:
                return None
            now = time.monotonic()
            if not deadline:
                deadline = now + wait
            elif now >= deadline:
                # the subscriber keeps its messages (a cache, a synchronizer): stop waiting until
                # a slot is seen free again, so one stall is all such a user ever pays
                self._patient = False
                return None
            time.sleep(_POLL)

    def _reserve(self, slot: int, end: int) -> bool:
        """Back the first ``end`` bytes of ``slot`` with tmpfs pages (lock held); False when
        /dev/shm is full (the caller then goes inline rather than taking a SIGBUS on the copy)."""
        if self._reserved[slot] < end:
            base = self._data + slot * self.slot_size
            try:
                os.posix_fallocate(self._fd, base, end)  # type: ignore[arg-type]
            except OSError:
                return False
            try:  # map the new pages in one call, not ~1500 faults for 6 MB on the first copy
                self._mm.madvise(_MADV_POPULATE_WRITE, base, end)
            except (OSError, ValueError):
                pass  # Linux before 5.14: the copy faults them in
            self._reserved[slot] = end
        return True

    def _fill(self, slot: int, parts: list, length: int) -> bytes | None:
        """Copy into ``slot`` and stamp it (lock held)."""
        if not self._reserve(slot, length):
            return None
        self._write(self._data + slot * self.slot_size, parts)
        return self._stamp(slot, 0, length)

    def _write(self, at: int, parts: list) -> None:
        mm = self._mm
        for part in parts:
            size = len(part)
            mm[at : at + size] = part
            at += size

    def _stamp(self, slot: int, offset: int, length: int) -> bytes:
        self._counter += 1
        gen = self._counter
        self._gen[slot] = gen
        _WORD.pack_into(self._mm, _CTL + 16 * slot, gen)
        return struct.pack("<I", NOTICE.size) + NOTICE.pack(NOTICE_TAG, slot, gen, offset, length)

    # -- loans: the user writes the big array straight into a slot -----------------------------

    @property
    def lending(self) -> bool:
        """Some slot is loaned out (publish then looks for the loaned array among its parts)."""
        return True in self._lent

    def lend(self, nbytes: int, wait: float = 0.0) -> Any:
        """A writable numpy ``uint8`` array of ``nbytes`` at :data:`LOAN_OFFSET` of a free slot, or
        None (no slot free after ``wait`` seconds, too big for a slot, /dev/shm full, ring closed).
        The slot stays busy while any view of that array lives, published or not, and after that
        until the subscriber releases what was published from it: a loan can never alias a message
        still being read."""
        if nbytes <= 0 or LOAN_OFFSET + nbytes > self.slot_size:
            return None
        import numpy

        lease = self._with_free_slot(wait, lambda slot: self._lease(slot, nbytes))
        return None if lease is None else numpy.frombuffer(lease, dtype=numpy.uint8)

    def _lease(self, slot: int, nbytes: int) -> Any:
        """Lend ``slot`` (lock held): the ctypes object exporting its array, or None."""
        import ctypes  # only a lending publisher needs it

        if not self._reserve(slot, LOAN_OFFSET + nbytes):
            return None
        if not self._address:
            probe = ctypes.c_char.from_buffer(self._mm)
            self._address = ctypes.addressof(probe)
            del probe
        lease_type = self._lease_types.get(nbytes)
        if lease_type is None:
            lease_type = self._lease_types[nbytes] = _loan_type(nbytes)
        lease = lease_type.from_buffer(self._mm, self._data + slot * self.slot_size + LOAN_OFFSET)
        lease.lent, lease.slot = self._lent, slot
        self._lent[slot] = True
        return lease

    def put_lent(self, parts: list, length: int) -> bytes | None:
        """Publish a message whose big array is loaned from this ring without copying it: the parts
        before the array are written just in front of it, the parts after it right behind, and the
        notice names that span. None when no part lies in a loaned slot of this ring, or that slot's
        last message is still unread (a loan published twice), or the fields around it do not fit:
        the caller then copies, as for any message."""
        import ctypes

        start, end = self._address + self._data, self._address + self._data + self.slots * self.slot_size
        for i, part in enumerate(parts):
            if len(part) < LOAN_OFFSET or not isinstance(part, memoryview) or part.readonly:
                continue
            try:
                probe = ctypes.c_char.from_buffer(part)
            except (TypeError, ValueError):
                continue
            address = ctypes.addressof(probe)
            del probe
            if not start <= address < end:
                continue
            slot, at = divmod(address - start, self.slot_size)
            before = sum(map(len, parts[:i]))
            after = length - before - len(part)
            with self._lock:
                gen = self._gen[slot]
                unread = (
                    gen
                    and self._reclaimed[slot] != gen
                    and _WORD.unpack_from(self._mm, _CTL + 16 * slot + 8)[0] != gen
                )
                if (
                    self.closed
                    or not self._lent[slot]
                    or unread
                    or before > at
                    or at + len(part) + after > self.slot_size
                    or not self._reserve(slot, at + len(part) + after)
                ):
                    return None
                base = self._data + slot * self.slot_size
                self._write(base + at - before, parts[:i])
                self._write(base + at + len(part), parts[i + 1 :])
                return self._stamp(slot, at - before, length)
        return None

    def reclaim(self, notice_frame: bytes) -> None:
        """A notice was dropped before it was sent (``queue_size``): its slot is free again."""
        try:
            _, slot, gen, _, _ = NOTICE.unpack_from(notice_frame, 4)
        except struct.error:
            return
        with self._lock:
            if slot < self.slots and self._gen[slot] == gen:
                self._reclaimed[slot] = gen

    def unlink(self) -> None:
        try:
            os.unlink(self.path)
        except OSError:
            pass

    def close(self) -> None:
        """Unlink the name and unmap (the subscriber keeps its own mapping while it has views)."""
        with self._lock:
            if self.closed:
                return
            self.closed = True
            self.unlink()
            if self._fd is not None:
                os.close(self._fd)
                self._fd = None
            try:
                self._mm.close()
            except BufferError:
                pass  # a loan is still held: the mapping goes with its last view


def _loan_type(nbytes: int) -> Any:
    """A ctypes array type of ``nbytes`` whose instances export one loaned slot; when the last view
    of one goes, its slot is lent no more (it may still wait for the subscriber to release it)."""
    import ctypes

    class Loan(ctypes.c_ubyte * nbytes):  # type: ignore[misc]
        def __del__(self) -> None:
            try:
                self.lent[self.slot] = False  # one list store: no lock (the GC may run anywhere)
            except Exception:  # interpreter shutdown: nothing left to tell
                pass

    return Loan


def is_notice(frame: bytes | bytearray) -> bool:
    return len(frame) == 4 + NOTICE.size and frame[4] == NOTICE_TAG


def is_announcement(frame: bytes | bytearray) -> bool:
    return len(frame) > 5 and frame[4] == RING_TAG


class ReaderRing:
    """The subscriber's side: maps the segment (then unlinks its name), checks notices and hands out
    read-only views whose slot is released when the last view of it is gone."""

    def __init__(self, name: str) -> None:
        if not name.startswith(PREFIX) or "/" in name:
            raise ShmError(f"not a ninjemys segment name: {name!r}")
        path = os.path.join(SHM_DIR, name)
        try:
            fd = os.open(path, os.O_RDWR)
        except OSError as exc:
            raise ShmError(f"cannot open {path}: {exc}") from None
        try:
            size = os.fstat(fd).st_size
            if size < _HEAD.size:
                raise ShmError(f"{path}: {size} bytes, too short for a ring header")
            self._mm = mmap.mmap(fd, size)
        except OSError as exc:
            raise ShmError(f"cannot map {path}: {exc}") from None
        finally:
            os.close(fd)
            try:
                os.unlink(path)  # both sides have it mapped now: nothing to leak
            except OSError:
                pass
        magic, slots, _, slot_size = _HEAD.unpack_from(self._mm, 0)
        data = _data_offset(slots)
        if magic != MAGIC or slots == 0 or data + slots * slot_size > size:
            self._mm.close()
            raise ShmError(
                f"{path}: not a ring this version understands ({slots} slots of {slot_size} bytes)"
            )
        self.slots, self.slot_size, self._data = slots, slot_size, data
        self._seen = [0] * slots
        import ctypes  # only a subscriber of a ring needs it (about 2 ms of start-up otherwise)

        class Lease(ctypes.c_ubyte * slot_size):  # type: ignore[misc]
            """Exports one slot; when the last view of it goes, the slot is released. It refers to
            the mapping itself (``mm``), not to the ring: no reference cycle, so the mapping goes
            the moment the connection and the last view are gone, without waiting for the GC."""

            def __del__(self) -> None:
                try:
                    _WORD.pack_into(self.mm, self.released_at, self.gen)
                except Exception:  # interpreter shutdown: nothing left to tell
                    pass

        self._lease = Lease

    def view(self, frame: bytes | bytearray) -> memoryview:
        """The payload a notice frame (without its length prefix) names, as a read-only view.
        Raises ShmError naming what is wrong: slot out of range, length beyond the slot, or a
        generation the publisher did not stamp (stale, replayed or forged)."""
        try:
            _, slot, gen, offset, length = NOTICE.unpack_from(frame, 0)
        except struct.error:
            raise ShmError(f"a {len(frame)}-byte notice") from None
        if slot >= self.slots:
            raise ShmError(f"slot {slot} out of range (ring of {self.slots})")
        if offset + length > self.slot_size:
            raise ShmError(f"length {length} at offset {offset} beyond the {self.slot_size}-byte slot")
        stamped = _WORD.unpack_from(self._mm, _CTL + 16 * slot)[0]
        if gen != stamped or gen <= self._seen[slot]:
            raise ShmError(
                f"slot {slot}: generation {gen}, expected {stamped} (newer than {self._seen[slot]})"
            )
        self._seen[slot] = gen
        lease = self._lease.from_buffer(self._mm, self._data + slot * self.slot_size)
        lease.mm, lease.released_at, lease.gen = self._mm, _CTL + 16 * slot + 8, gen
        view = memoryview(lease).cast("B")[offset : offset + length].toreadonly()
        return view
