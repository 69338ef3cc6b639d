"""The RPLIDAR's dense (0x85) and ultra (0x84) capsules: the A2M12/A3/S-series scan modes, sans I/O.

Both share the express capsule's framing (:class:`ninjemys.drivers.rplidar_protocol.CapsuleDecoder`:
sync nibbles, XOR checksum, start flag) and, like it, a capsule's samples are spread evenly from its
start angle to the next capsule's, so they come out when the next capsule arrives.

* **Dense** (84 bytes): 40 little-endian uint16 distances in millimetres, no angle compensation.
* **Ultra** (132 bytes; Boost, Sensitivity and Stability on an A3): 32 uint32 "cabins" of three samples:
  bits 0-11 a *major* distance in Slamtec's variable bit scale (1 mm steps up to 511 mm, then 2, 4, 8 and
  16 mm steps), bits 12-21 and 22-31 two signed 10-bit *predictions*: the second sample is the major
  plus prediction 1 scaled like the major, the third the next cabin's major plus prediction 2 scaled
  like that one (-512 and 511 mean "no echo"). Each sample's angle is its interpolated angle minus a
  distance-dependent compensation (7.5 degrees for echoes closer than 50 mm, about 8 degrees less a
  near-field term otherwise), all in the SDK's integer arithmetic.

The arithmetic follows Slamtec's SDK 1.12 (rplidar_ros 1.10) integer for integer, on arrays: one row
per capsule, so a read of many capsules is a few numpy passes. ``pack_*`` build capsules from samples
(what emulated devices send).
"""

from __future__ import annotations

import functools
import math
import struct

import numpy as np

from ninjemys.drivers import rplidar_protocol as rp

DENSE_SAMPLES = 40
ULTRA_CABINS = 32
ULTRA_SAMPLES = 3 * ULTRA_CABINS
#: variable bit scale: (first scaled value, shift, first decoded value), from the coarsest step down
_VBS = ((3328, 4, 1 << 14), (1792, 3, 1 << 12), (1280, 2, 1 << 11), (512, 1, 1 << 9), (0, 0, 0))
#: the ultra angle compensation's constants (radians in 1/65536, as the SDK truncates them)
_OFFSET_NEAR_Q16 = int(7.5 * 3.1415926535 * (1 << 16) / 180.0)
_OFFSET_BASE_Q16 = int(8 * 3.1415926535 * (1 << 16) / 180)
#: predictions that mean "no echo": -512 and 511 (0xFFFFFE00 and 0x1FF in the SDK's 32-bit ints)


def varbitscale_decode(scaled: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Millimetres and shift of 12-bit scaled majors (arrays), looked up in a 4096-entry table."""
    values, shifts = _vbs_tables()
    return values[scaled], shifts[scaled]


@functools.cache
def _vbs_tables() -> tuple[np.ndarray, np.ndarray]:
    """Every 12-bit scaled major's millimetres and shift (built on first use: no work at import)."""
    scaled = np.arange(4096, dtype=np.int64)
    value = np.zeros(4096, dtype=np.int64)
    shift = np.zeros(4096, dtype=np.int64)
    done = np.zeros(4096, dtype=bool)
    for base, level, target in _VBS:
        hit = ~done & (scaled >= base)
        value[hit] = target + ((scaled[hit] - base) << level)
        shift[hit] = level
        done |= hit
    return value, shift


def varbitscale_encode(mm: int) -> int:
    """The scaled major of a distance in millimetres (rounded to the nearest step of its scale)."""
    for base, level, target in _VBS:
        if mm >= target:
            return min(base + ((mm - target + ((1 << level) >> 1)) >> level), 0xFFF)
    return 0


def _start_q8(capsules: list[bytes]) -> np.ndarray:
    """Each capsule's start angle in 1/256 degree (its 15-bit q6 field, shifted)."""
    words = np.frombuffer(b"".join(c[2:4] for c in capsules), dtype="<u2").astype(np.int64)
    return (words & 0x7FFF) << 2


def _angles(prevs: list[bytes], curs: list[bytes], per_capsule: int) -> tuple[np.ndarray, np.ndarray]:
    """Each sample's raw angle (degrees in 1/65536 << 6, the SDK's q16) and the angle step per sample."""
    prev_q8, cur_q8 = _start_q8(prevs), _start_q8(curs)
    diff_q8 = cur_q8 - prev_q8 + np.where(prev_q8 > cur_q8, 360 << 8, 0)
    inc_q16 = ((diff_q8 << 8) // per_capsule)[:, None]
    raw_q16 = (prev_q8 << 8)[:, None] + np.arange(per_capsule, dtype=np.int64)[None, :] * inc_q16
    return raw_q16, inc_q16


def _rows(angle_q6: np.ndarray, raw_q16: np.ndarray, inc_q16: np.ndarray, dist_q2: np.ndarray) -> np.ndarray:
    angle_q6 = np.where(angle_q6 < 0, angle_q6 + (360 << 6), angle_q6)
    angle_q6 = np.where(angle_q6 >= (360 << 6), angle_q6 - (360 << 6), angle_q6)
    start = ((raw_q16 + inc_q16) % (360 << 16)) < inc_q16
    out = np.empty((angle_q6.size, 4), dtype=np.float64)
    out[:, 0] = rp.q14_degrees(angle_q6).ravel()
    out[:, 1] = (dist_q2 / 4.0).ravel()
    out[:, 2] = np.where(dist_q2 != 0, 0x2F, 0).ravel()
    out[:, 3] = start.ravel()
    return out


def dense_samples(prevs: list[bytes], curs: list[bytes]) -> np.ndarray:
    """Rows (angle deg, distance mm, quality, start) of each dense capsule in ``prevs``."""
    raw_q16, inc_q16 = _angles(prevs, curs, DENSE_SAMPLES)
    body = b"".join(c[4:] for c in prevs)
    dist = np.frombuffer(body, dtype="<u2").reshape(len(prevs), DENSE_SAMPLES).astype(np.int64)
    return _rows(raw_q16 >> 10, raw_q16, inc_q16, dist << 2)


def ultra_samples(prevs: list[bytes], curs: list[bytes]) -> np.ndarray:
    """Rows (angle deg, distance mm, quality, start) of each ultra capsule in ``prevs``."""
    n = len(prevs)
    raw_q16, inc_q16 = _angles(prevs, curs, ULTRA_SAMPLES)
    body = b"".join(c[4:] for c in prevs)
    combined = np.frombuffer(body, dtype="<u4").reshape(n, ULTRA_CABINS).astype(np.int64)
    next_first = np.frombuffer(b"".join(c[4:8] for c in curs), dtype="<u4").astype(np.int64)
    major_raw = combined & 0xFFF
    major2_raw = np.concatenate([major_raw[:, 1:], (next_first & 0xFFF)[:, None]], axis=1)
    predict1 = (combined >> 12) & 0x3FF
    predict1 = np.where(predict1 >= 512, predict1 - 1024, predict1)
    predict2 = (combined >> 22) & 0x3FF
    predict2 = np.where(predict2 >= 512, predict2 - 1024, predict2)
    major, scale1 = varbitscale_decode(major_raw)
    major2, scale2 = varbitscale_decode(major2_raw)
    borrow = (major == 0) & (major2 != 0)  # no major echo: the first prediction leans on the next one
    base1 = np.where(borrow, major2, major)
    scale1 = np.where(borrow, scale2, scale1)
    d0 = major << 2
    d1 = np.where((predict1 == -512) | (predict1 == 0x1FF), 0, ((predict1 << scale1) + base1) << 2)
    d2 = np.where((predict2 == -512) | (predict2 == 0x1FF), 0, ((predict2 << scale2) + major2) << 2)
    dist_q2 = np.stack([d0, d1, d2], axis=2).reshape(n, ULTRA_SAMPLES)
    dist_q2 = np.maximum(dist_q2, 0)  # a negative prediction sum is no echo, not a 4-billion-mm one
    offset_q16 = np.full(dist_q2.shape, _OFFSET_NEAR_Q16, dtype=np.int64)
    far = dist_q2 >= 50 * 4
    k2 = 98361 // np.where(far, dist_q2, 1)
    offset_q16 = np.where(far, _OFFSET_BASE_Q16 - (k2 << 6) - (k2 * k2 * k2) // 98304, offset_q16)
    offset_deg_q16 = np.trunc(offset_q16 * 180 / 3.14159265).astype(np.int64)
    return _rows((raw_q16 - offset_deg_q16) >> 10, raw_q16, inc_q16, dist_q2)


def ultra_offset_deg(dist_mm: int) -> float:
    """Degrees the decoder subtracts from an ultra sample's interpolated angle (for emulators)."""
    dist_q2 = dist_mm << 2
    if dist_q2 >= 200:
        k2 = 98361 // dist_q2
        offset = _OFFSET_BASE_Q16 - (k2 << 6) - (k2 * k2 * k2) // 98304
    else:
        offset = _OFFSET_NEAR_Q16
    return math.trunc(offset * 180 / 3.14159265) / 65536.0


def _frame(start_angle_deg: float, start: bool, body: bytes) -> bytes:
    start_q6 = int(round(start_angle_deg * 64.0)) % (360 * 64)
    payload = struct.pack("<H", start_q6 | (0x8000 if start else 0)) + body
    cs = 0
    for b in payload:
        cs ^= b
    return bytes((0xA0 | (cs & 0xF), 0x50 | (cs >> 4))) + payload


def pack_dense_capsule(start_angle_deg: float, dists_mm: list[int], start: bool) -> bytes:
    """One dense capsule: 40 distances in millimetres."""
    if len(dists_mm) != DENSE_SAMPLES:
        raise ValueError("a dense capsule carries 40 samples")
    return _frame(start_angle_deg, start, struct.pack("<40H", *(min(max(d, 0), 0xFFFF) for d in dists_mm)))


def ultra_decoded_mm(majors: list[int]) -> list[tuple[int, int]]:
    """(millimetres, shift) each scaled major decodes to."""
    value, shift = varbitscale_decode(np.array(majors, dtype=np.int64))
    return list(zip(value.tolist(), shift.tolist(), strict=True))


def pack_ultra_cabins(samples_mm: list[int], next_major: int) -> tuple[bytes, list[int]]:
    """32 cabins for 96 distances (mm, 0 = no echo) and the distances they decode to.

    ``next_major`` is the scaled major of the next capsule's first cabin (the last cabin's third sample
    is predicted from it). A prediction out of the 10-bit range is sent as "no echo".
    """
    if len(samples_mm) != ULTRA_SAMPLES:
        raise ValueError("an ultra capsule carries 96 samples")
    majors = [varbitscale_encode(samples_mm[3 * i]) for i in range(ULTRA_CABINS)]
    decoded = ultra_decoded_mm([*majors, next_major])
    words, out = [], []
    for i in range(ULTRA_CABINS):
        (m1, s1), (m2, s2) = decoded[i], decoded[i + 1]
        base1, shift1 = (m2, s2) if m1 == 0 and m2 != 0 else (m1, s1)
        p1, d1 = _predict(samples_mm[3 * i + 1], base1, shift1)
        p2, d2 = _predict(samples_mm[3 * i + 2], m2, s2)
        words.append(majors[i] | (p1 & 0x3FF) << 12 | (p2 & 0x3FF) << 22)
        out += [m1, d1, d2]
    return struct.pack(f"<{ULTRA_CABINS}I", *words), out


def _predict(mm: int, base: int, shift: int) -> tuple[int, int]:
    if mm <= 0:
        return 0x1FF, 0
    p = (mm - base + ((1 << shift) >> 1)) >> shift
    if not -511 <= p <= 510:
        return 0x1FF, 0
    return p, (p << shift) + base


def pack_ultra_capsule(start_angle_deg: float, cabins: bytes, start: bool) -> bytes:
    """One ultra capsule around 32 packed cabins (:func:`pack_ultra_cabins`)."""
    if len(cabins) != 4 * ULTRA_CABINS:
        raise ValueError("an ultra capsule carries 32 cabins of 4 bytes")
    return _frame(start_angle_deg, start, cabins)
