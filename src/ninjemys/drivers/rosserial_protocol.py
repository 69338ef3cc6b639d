"""The rosserial wire protocol (Hydro and later, as rosserial_arduino 0.9 speaks it), sans I/O.

A packet is::

    0xFF  0xFE  len_lo len_hi  len_checksum  topic_lo topic_hi  payload...  msg_checksum

``0xFE`` is the protocol version byte (Groovy's clients sent ``0xFF``). ``len_checksum`` makes the two
length bytes sum to 255 modulo 256, ``msg_checksum`` does the same for the two topic bytes and the
payload. The payload is the ROS 1 serialization of the message. Topic ids below 100 are the
protocol's own (``rosserial_msgs/TopicInfo``'s constants); device topics have ids from 100 on.

:class:`FrameReader` turns a byte stream into :class:`Frame` s and :class:`Drop` s: a bad length or
message checksum, a wrong version byte, or stray bytes drop what they spoil and reading resynchronises
on the next ``0xFF 0xFE`` with no restart. Nothing here reads a port or a clock: the host
(:mod:`ninjemys.drivers.rosserial_host`) and the test devices share it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

SYNC = 0xFF
PROTOCOL_VER = 0xFE
PROTOCOL_VER_GROOVY = 0xFF

ID_PUBLISHER = 0
ID_SUBSCRIBER = 1
ID_SERVICE_SERVER = 2
ID_SERVICE_CLIENT = 4
ID_PARAMETER_REQUEST = 6
ID_LOG = 7
ID_TIME = 10
ID_TX_STOP = 11

#: the longest payload a 16-bit length field can carry
MAX_PAYLOAD = 0xFFFF


def checksum(data: bytes | bytearray) -> int:
    """The byte that makes ``data`` plus itself sum to 255 modulo 256."""
    return 255 - (sum(data) % 256)


def frame(topic_id: int, payload: bytes | bytearray = b"") -> bytes:
    """One packet carrying ``payload`` on ``topic_id``."""
    if len(payload) > MAX_PAYLOAD:
        raise ValueError(f"rosserial payload of {len(payload)} bytes exceeds {MAX_PAYLOAD}")
    length = len(payload).to_bytes(2, "little")
    topic = topic_id.to_bytes(2, "little")
    return bytes(
        (SYNC, PROTOCOL_VER, *length, checksum(length), *topic, *payload, checksum(topic + bytes(payload)))
    )


#: what the host sends to ask the device for its topics (an empty packet on ID_PUBLISHER)
REQUEST_TOPICS = frame(ID_PUBLISHER)
#: what the host sends when it stops (an empty packet on ID_TX_STOP)
TX_STOP = frame(ID_TX_STOP)


@dataclass(frozen=True)
class Frame:
    """A packet whose checksums hold."""

    topic_id: int
    payload: bytes


class DropReason(Enum):
    VERSION = "version"  # the byte after 0xFF is not 0xFE
    LENGTH_CHECKSUM = "length checksum"
    MSG_CHECKSUM = "message checksum"


@dataclass(frozen=True)
class Drop:
    """A packet thrown away; ``detail`` is the version byte, the length, or the topic id."""

    reason: DropReason
    detail: int

    def log_line(self) -> str:
        """The first (main) line rosserial_python logs for it."""
        return self.log_lines()[0][1]

    def log_lines(self) -> list[tuple[str, str]]:
        """``(level, line)`` as rosserial_python (noetic) logs them: a version mismatch is an error
        followed by an info line naming both protocol versions; the checksum drops are info lines."""
        if self.reason is DropReason.VERSION:
            found = _PROTOCOL_REVISIONS.get(self.detail)
            client = (
                f"Protocol version of client is {found}"
                if found
                else ("Protocol version of client is unrecognized")
            )
            return [
                (
                    "error",
                    f"Mismatched protocol version in packet ({bytes([self.detail])!r}): lost sync or "
                    "rosserial_python is from different ros release than the rosserial client",
                ),
                ("info", f"{client}, expected {_PROTOCOL_REVISIONS[PROTOCOL_VER]}"),
            ]
        if self.reason is DropReason.LENGTH_CHECKSUM:
            length = self.detail - 0x10000 if self.detail >= 0x8000 else self.detail  # read as "<h"
            return [("info", f"Wrong checksum for msg length, length {length}, dropping message.")]
        return [("info", "wrong checksum for topic id and msg")]


#: the version byte's meaning, in rosserial_python's words
_PROTOCOL_REVISIONS = {
    0xFF: "Rev 0 (rosserial 0.4 and earlier)",
    0xFE: "Rev 1 (rosserial 0.5+)",
    0xFD: "Some future rosserial version",
}


class FrameReader:
    """Incremental packet parser: ``feed(bytes)`` returns the packets and drops completed by them.

    Bytes before a ``0xFF`` are skipped silently (a board's boot banner, line noise), as rosserial's
    hosts do. The reader keeps only the bytes of the packet under way.
    """

    def __init__(self) -> None:
        self._buf = bytearray()
        self.skipped = 0  # bytes thrown away while looking for a packet start

    def feed(self, data: bytes | bytearray) -> list[Frame | Drop]:
        self._buf += data
        out: list[Frame | Drop] = []
        buf = self._buf
        while True:
            start = buf.find(SYNC)
            if start < 0:
                self.skipped += len(buf)
                buf.clear()
                break
            if start:
                self.skipped += start
                del buf[:start]
            if len(buf) < 2:
                break
            if buf[1] != PROTOCOL_VER:
                if buf[1] == SYNC:
                    if len(buf) < 3:
                        break
                    if buf[2] == PROTOCOL_VER:  # 0xFF 0xFF 0xFE: a stray 0xFF before a real packet
                        self.skipped += 1
                        del buf[:1]
                        continue
                    # 0xFF 0xFF then no 0xFE: a Groovy (protocol rev 0) client, as rosserial_python sees it
                out.append(Drop(DropReason.VERSION, buf[1]))
                self.skipped += 2
                del buf[:2]
                continue
            if len(buf) < 5:
                break
            length = buf[2] | buf[3] << 8
            if (buf[2] + buf[3] + buf[4]) % 256 != 255:
                out.append(Drop(DropReason.LENGTH_CHECKSUM, length))
                self.skipped += 2
                del buf[:2]  # resynchronise on the next 0xFF after the bad header
                continue
            total = 8 + length
            if len(buf) < total:
                break
            topic_id = buf[5] | buf[6] << 8
            if sum(buf[5:total]) % 256 != 255:
                out.append(Drop(DropReason.MSG_CHECKSUM, topic_id))
                self.skipped += 2
                del buf[:2]
                continue
            out.append(Frame(topic_id, bytes(buf[7 : total - 1])))
            del buf[:total]
        return out
