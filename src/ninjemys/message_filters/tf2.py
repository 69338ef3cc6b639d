"""tf2's MessageFilter: hold stamped messages until they can be transformed into the target frame(s).

ROS 1 has it only in C++ (``tf2_ros::MessageFilter``); this is that filter for Python, with its
names: ``setTargetFrame(s)``, ``setTolerance``, ``setQueueSize``, ``registerFailureCallback``,
``clear``, and the failure reasons ``Unknown`` (pushed out of a full queue, or its transform
never came), ``OutTheBack`` (older than the buffer's history: it can never be transformed) and
``EmptyFrameID``.

The buffer is any object with tf2_ros.Buffer's ``can_transform(target, source, time,
return_debug_tuple=True)``. When it also offers ``add_change_listener(fn)`` (ninjemys'
tf2 buffer does), held messages are re-checked each time new transforms arrive, on the thread that
inserted them; otherwise they are re-checked whenever a new message comes in.
"""

from __future__ import annotations

import enum
import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

from ninjemys.message_filters import SimpleFilter

_log = logging.getLogger("message_filters.tf2")


class FilterFailureReason(enum.IntEnum):
    """Why a message was dropped (``tf2_ros::filter_failure_reasons``)."""

    Unknown = 0
    OutTheBack = 1
    EmptyFrameID = 2


class MessageFilter(SimpleFilter):
    """Passes each message on once ``buffer`` can transform its frame to every target frame.

    ``queue_size`` messages wait at most (0 = unbounded); the oldest is dropped (reason ``Unknown``)
    to make room. Failure callbacks get ``(msg, reason)``.
    """

    def __init__(
        self,
        f: SimpleFilter | None,
        buffer: Any,
        target_frame: str | Sequence[str],
        queue_size: int,
        tolerance: float = 0.0,
    ) -> None:
        super().__init__()
        self.buffer = buffer
        self._lock = threading.RLock()
        self._pending: deque[Any] = deque()
        self._failure_callbacks: dict[int, Callable[[Any, FilterFailureReason], Any]] = {}
        self._queue_size = queue_size
        self._tolerance_ns = round(tolerance * 1e9)
        self._targets: list[str] = []
        self.setTargetFrames([target_frame] if isinstance(target_frame, str) else list(target_frame))
        self.incoming = 0
        self.dropped = 0
        self.out_the_back = 0
        self._next_warning = time.monotonic() + 15.0
        listen = getattr(buffer, "add_change_listener", None)
        self._listens = listen is not None
        if listen is not None:
            listen(self._recheck)
        if f is not None:
            self.connectInput(f)

    # -- configuration -----------------------------------------------------------------------------
    def connectInput(self, f: SimpleFilter) -> None:  # noqa: N802 - ROS 1 API
        self.incoming_connection = f.registerCallback(self.add)

    def setTargetFrame(self, target_frame: str) -> None:  # noqa: N802 - ROS 1 API
        self.setTargetFrames([target_frame])

    def setTargetFrames(self, target_frames: Sequence[str]) -> None:  # noqa: N802 - ROS 1 API
        with self._lock:
            self._targets = [t.lstrip("/") for t in target_frames if t]

    def getTargetFramesString(self) -> str:  # noqa: N802 - ROS 1 API
        return "".join(t + " " for t in self._targets)

    def setTolerance(self, tolerance: Any) -> None:  # noqa: N802 - ROS 1 API
        """Also require the transform ``tolerance`` after the stamp (seconds, or a Duration)."""
        seconds = tolerance if isinstance(tolerance, int | float) else tolerance.to_sec()
        self._tolerance_ns = round(seconds * 1e9)

    def setQueueSize(self, queue_size: int) -> None:  # noqa: N802 - ROS 1 API
        self._queue_size = queue_size

    def getQueueSize(self) -> int:  # noqa: N802 - ROS 1 API
        return self._queue_size

    def registerFailureCallback(self, cb: Callable[[Any, FilterFailureReason], Any]) -> int:  # noqa: N802
        """Call ``cb(msg, reason)`` for every message this filter drops."""
        conn = max(self._failure_callbacks, default=-1) + 1
        self._failure_callbacks[conn] = cb
        return conn

    def clear(self) -> None:
        """Forget every waiting message (without failure notifications, as ROS 1)."""
        with self._lock:
            self._pending.clear()

    def pending(self) -> int:
        """How many messages are waiting for their transforms."""
        return len(self._pending)

    # -- flow --------------------------------------------------------------------------------------
    def _check(self, msg: Any) -> FilterFailureReason | bool:
        """True when transformable now, False to keep waiting, or the reason to drop it."""
        header = msg.header
        frame = header.frame_id.lstrip("/")
        if not frame:
            return FilterFailureReason.EmptyFrameID
        stamp = header.stamp
        times = [stamp]
        if self._tolerance_ns:
            secs, nsecs = divmod(stamp.secs * 1_000_000_000 + stamp.nsecs + self._tolerance_ns, 1_000_000_000)
            times.append(type(stamp)(secs, nsecs))
        for target in self._targets:
            for t in times:
                ok, why = self.buffer.can_transform(target, frame, t, return_debug_tuple=True)
                if not ok:
                    return FilterFailureReason.OutTheBack if "into the past" in why else False
        return True

    def add(self, msg: Any) -> None:
        """Take one message: pass it on now, hold it, or drop it (with notification)."""
        if not self._targets:
            return
        with self._lock:
            self.incoming += 1
            verdict = self._check(msg)
            if verdict is False:
                if self._queue_size and len(self._pending) + 1 > self._queue_size:
                    self._drop(self._pending.popleft(), FilterFailureReason.Unknown)
                self._pending.append(msg)
        if verdict is True:
            self.signalMessage(msg)
        elif verdict is not False:
            self._drop(msg, verdict)
        if not self._listens:
            self._recheck()

    def _recheck(self) -> None:
        """Re-test every held message (oldest first); pass on the ready ones, drop the hopeless ones."""
        if not self._pending:
            return
        ready: list[Any] = []
        dropped: list[tuple[Any, FilterFailureReason]] = []
        with self._lock:
            keep: deque[Any] = deque()
            for msg in self._pending:
                verdict = self._check(msg)
                if verdict is True:
                    ready.append(msg)
                elif verdict is False:
                    keep.append(msg)
                else:
                    dropped.append((msg, verdict))
            self._pending = keep
        for msg in ready:
            self.signalMessage(msg)
        for msg, reason in dropped:
            self._drop(msg, reason)

    def _drop(self, msg: Any, reason: FilterFailureReason) -> None:
        self.dropped += 1
        if reason is FilterFailureReason.OutTheBack:
            self.out_the_back += 1
        header = msg.header
        _log.debug(
            "MessageFilter [target=%s]: dropped message: frame '%s' at time %.3f for reason '%s'",
            self.getTargetFramesString(),
            header.frame_id,
            header.stamp.secs + header.stamp.nsecs * 1e-9,
            reason.name,
        )
        for cb in list(self._failure_callbacks.values()):
            cb(msg, reason)
        self._check_failures()

    def _check_failures(self) -> None:
        """ROS 1's periodic warning when nearly everything is being dropped (at most once a minute)."""
        now = time.monotonic()
        done = self.incoming - len(self._pending)
        if now < self._next_warning or done <= 0:
            return
        share = self.dropped / done
        if share > 0.95:
            _log.warning(
                "MessageFilter [target=%s]: Dropped %.2f%% of messages so far (%d of them older than the TF cache).",
                self.getTargetFramesString(),
                share * 100,
                self.out_the_back,
            )
            self._next_warning = now + 60.0
