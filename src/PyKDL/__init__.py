"""PyKDL's frames in pure Python: Vector, Rotation, Frame, Twist, Wrench and the free functions
(dot, diff, addDelta, Equal, SetToZero) with KDL's arithmetic, so the numbers match Debian's
C++ PyKDL to rounding, and with its printing (``%12g`` columns), indexing and errors.

Why: tf_conversions.posemath and many robot scripts import PyKDL only for frame arithmetic; the
chains, solvers and trees of orocos-kdl are not provided. ``==`` is KDL's ``Equal`` (1e-6), as in
PyKDL.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

__all__ = [
    "Equal",
    "Frame",
    "Rotation",
    "SetToZero",
    "Twist",
    "Vector",
    "Wrench",
    "addDelta",
    "changeBase",
    "changeRefPoint",
    "diff",
    "dot",
]

epsilon = 1e-6
_SMALL = 1e-12


def _g(value: float) -> str:
    return "%12g" % value


class Vector:
    """A 3-vector; ``*`` between vectors is the cross product, as in KDL."""

    __slots__ = ("_d",)

    def __init__(self, *args: Any) -> None:
        if not args:
            self._d = [0.0, 0.0, 0.0]
        elif len(args) == 1 and isinstance(args[0], Vector):
            self._d = list(args[0]._d)
        elif len(args) == 3:
            self._d = [float(a) for a in args]
        else:
            raise TypeError("Vector(): arguments did not match any overloaded call")

    @classmethod
    def _raw(cls, x: float, y: float, z: float) -> Vector:
        v = cls.__new__(cls)
        v._d = [x, y, z]
        return v

    def x(self, value: float | None = None) -> float | None:
        if value is None:
            return self._d[0]
        self._d[0] = float(value)
        return None

    def y(self, value: float | None = None) -> float | None:
        if value is None:
            return self._d[1]
        self._d[1] = float(value)
        return None

    def z(self, value: float | None = None) -> float | None:
        if value is None:
            return self._d[2]
        self._d[2] = float(value)
        return None

    def __getitem__(self, i: int) -> float:
        if not isinstance(i, int) or i < 0 or i > 2:
            raise IndexError("Vector index out of range")
        return self._d[i]

    def __setitem__(self, i: int, value: float) -> None:
        if not isinstance(i, int) or i < 0 or i > 2:
            raise IndexError("Vector index out of range")
        self._d[i] = float(value)

    def __len__(self) -> int:
        return 3

    def __iter__(self) -> Iterator[float]:
        return iter(list(self._d))

    def Norm(self, eps: float = 1e-9) -> float:
        a, b, c = self._d
        t1, t2 = abs(a), abs(b)
        if t1 >= t2:
            t2 = abs(c)
            if t1 >= t2:
                if t1 == 0:
                    return 0.0
                return t1 * math.sqrt(1 + (b / a) ** 2 + (c / a) ** 2)
            return t2 * math.sqrt(1 + (a / c) ** 2 + (b / c) ** 2)
        t1 = abs(c)
        if t2 > t1:
            return t2 * math.sqrt(1 + (a / b) ** 2 + (c / b) ** 2)
        return t1 * math.sqrt(1 + (a / c) ** 2 + (b / c) ** 2)

    def Normalize(self, eps: float = 1e-9) -> float:
        n = self.Norm()
        if n < eps:
            self._d = [1.0, 0.0, 0.0]
        else:
            self._d = [v / n for v in self._d]
        return n

    def ReverseSign(self) -> None:
        self._d = [-v for v in self._d]

    @staticmethod
    def Zero() -> Vector:
        return Vector()

    def __add__(self, o: Vector) -> Vector:
        if not isinstance(o, Vector):
            return NotImplemented
        a, b = self._d, o._d
        return Vector._raw(a[0] + b[0], a[1] + b[1], a[2] + b[2])

    def __sub__(self, o: Vector) -> Vector:
        if not isinstance(o, Vector):
            return NotImplemented
        a, b = self._d, o._d
        return Vector._raw(a[0] - b[0], a[1] - b[1], a[2] - b[2])

    def __iadd__(self, o: Vector) -> Vector:
        return self + o

    def __isub__(self, o: Vector) -> Vector:
        return self - o

    def __neg__(self) -> Vector:
        return Vector._raw(-self._d[0], -self._d[1], -self._d[2])

    def __pos__(self) -> Vector:
        return Vector(self)

    def __mul__(self, o: Any) -> Vector:
        if isinstance(o, Vector):
            a, b = self._d, o._d
            return Vector._raw(
                a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]
            )
        if isinstance(o, (int, float)) and not isinstance(o, bool):
            return Vector._raw(self._d[0] * o, self._d[1] * o, self._d[2] * o)
        return NotImplemented

    def __rmul__(self, o: Any) -> Vector:
        if isinstance(o, (int, float)) and not isinstance(o, bool):
            return Vector._raw(o * self._d[0], o * self._d[1], o * self._d[2])
        return NotImplemented

    def __truediv__(self, o: Any) -> Vector:
        if isinstance(o, (int, float)) and not isinstance(o, bool):
            return Vector._raw(self._d[0] / o, self._d[1] / o, self._d[2] / o)
        return NotImplemented

    def __eq__(self, o: object) -> bool:
        return isinstance(o, Vector) and Equal(self, o)

    def __ne__(self, o: object) -> bool:
        return not self == o

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return "[" + ",".join(_g(v) for v in self._d) + "]"

    __str__ = __repr__

    def __reduce__(self) -> tuple[Any, ...]:
        return (Vector, tuple(self._d))

    def __copy__(self) -> Vector:
        return Vector(self)

    def __deepcopy__(self, memo: Any) -> Vector:
        return Vector(self)


class Rotation:
    """A 3x3 rotation matrix stored row by row, as KDL's ``data[9]``."""

    __slots__ = ("_d",)

    def __init__(self, *args: Any) -> None:
        if not args:
            self._d = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        elif len(args) == 1 and isinstance(args[0], Rotation):
            self._d = list(args[0]._d)
        elif len(args) == 9:
            self._d = [float(a) for a in args]
        elif len(args) == 3 and all(isinstance(a, Vector) for a in args):
            x, y, z = (a._d for a in args)
            self._d = [x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]]
        else:
            raise TypeError("Rotation(): arguments did not match any overloaded call")

    @classmethod
    def _raw(cls, d: list[float]) -> Rotation:
        r = cls.__new__(cls)
        r._d = d
        return r

    def __getitem__(self, ij: tuple[int, int]) -> float:
        i, j = _pair(ij, 2, 2, "Rotation")
        return self._d[3 * i + j]

    def __setitem__(self, ij: tuple[int, int], value: float) -> None:
        i, j = _pair(ij, 2, 2, "Rotation")
        self._d[3 * i + j] = float(value)

    @staticmethod
    def Identity() -> Rotation:
        return Rotation()

    @staticmethod
    def RotX(angle: float) -> Rotation:
        c, s = math.cos(angle), math.sin(angle)
        return Rotation._raw([1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c])

    @staticmethod
    def RotY(angle: float) -> Rotation:
        c, s = math.cos(angle), math.sin(angle)
        return Rotation._raw([c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c])

    @staticmethod
    def RotZ(angle: float) -> Rotation:
        c, s = math.cos(angle), math.sin(angle)
        return Rotation._raw([c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0])

    @staticmethod
    def Rot(axis: Vector, angle: float) -> Rotation:
        v = Vector(axis)
        if v.Normalize() < _SMALL:
            return Rotation()
        return Rotation.Rot2(v, angle)

    @staticmethod
    def Rot2(axis: Vector, angle: float) -> Rotation:
        a0, a1, a2 = axis._d
        ct, st = math.cos(angle), math.sin(angle)
        vt = 1 - ct
        v0, v1, v2 = vt * a0, vt * a1, vt * a2
        s0, s1, s2 = a0 * st, a1 * st, a2 * st
        v01, v02, v12 = v0 * a1, v0 * a2, v1 * a2
        return Rotation._raw(
            [
                ct + v0 * a0,
                -s2 + v01,
                s1 + v02,
                s2 + v01,
                ct + v1 * a1,
                -s0 + v12,
                -s1 + v02,
                s0 + v12,
                ct + v2 * a2,
            ]
        )

    @staticmethod
    def RPY(roll: float, pitch: float, yaw: float) -> Rotation:
        ca, sa = math.cos(yaw), math.sin(yaw)
        cb, sb = math.cos(pitch), math.sin(pitch)
        cc, sc = math.cos(roll), math.sin(roll)
        return Rotation._raw(
            [
                ca * cb, ca * sb * sc - sa * cc, ca * sb * cc + sa * sc,
                sa * cb, sa * sb * sc + ca * cc, sa * sb * cc - ca * sc,
                -sb, cb * sc, cb * cc,
            ]
        )  # fmt: skip

    @staticmethod
    def EulerZYX(alpha: float, beta: float, gamma: float) -> Rotation:
        return Rotation.RPY(gamma, beta, alpha)

    @staticmethod
    def EulerZYZ(alpha: float, beta: float, gamma: float) -> Rotation:
        sa, ca = math.sin(alpha), math.cos(alpha)
        sb, cb = math.sin(beta), math.cos(beta)
        sg, cg = math.sin(gamma), math.cos(gamma)
        return Rotation._raw(
            [
                ca * cb * cg - sa * sg, -ca * cb * sg - sa * cg, ca * sb,
                sa * cb * cg + ca * sg, -sa * cb * sg + ca * cg, sa * sb,
                -sb * cg, sb * sg, cb,
            ]
        )  # fmt: skip

    @staticmethod
    def Quaternion(x: float, y: float, z: float, w: float) -> Rotation:
        x2, y2, z2, w2 = x * x, y * y, z * z, w * w
        return Rotation._raw(
            [
                w2 + x2 - y2 - z2, 2 * x * y - 2 * w * z, 2 * x * z + 2 * w * y,
                2 * x * y + 2 * w * z, w2 - x2 + y2 - z2, 2 * y * z - 2 * w * x,
                2 * x * z - 2 * w * y, 2 * y * z + 2 * w * x, w2 - x2 - y2 + z2,
            ]
        )  # fmt: skip

    def GetRPY(self) -> tuple[float, float, float]:
        d = self._d
        pitch = math.atan2(-d[6], math.sqrt(d[0] * d[0] + d[3] * d[3]))
        if abs(pitch) > math.pi / 2.0 - _SMALL:
            return 0.0, pitch, math.atan2(-d[1], d[4])
        return math.atan2(d[7], d[8]), pitch, math.atan2(d[3], d[0])

    def GetEulerZYX(self) -> tuple[float, float, float]:
        roll, pitch, yaw = self.GetRPY()
        return yaw, pitch, roll

    def GetEulerZYZ(self) -> tuple[float, float, float]:
        d = self._d
        if abs(d[8]) > 1 - _SMALL:
            if d[8] > 0:
                return math.atan2(d[3], d[0]), 0.0, 0.0
            return math.atan2(-d[3], -d[0]), math.pi, 0.0
        alpha = math.atan2(d[5], d[2])
        beta = math.atan2(math.sqrt(d[6] * d[6] + d[7] * d[7]), d[8])
        return alpha, beta, math.atan2(d[7], -d[6])

    def GetQuaternion(self) -> tuple[float, float, float, float]:
        d = self._d
        trace = d[0] + d[4] + d[8]
        if trace > _SMALL:
            s = 0.5 / math.sqrt(trace + 1.0)
            return (d[7] - d[5]) * s, (d[2] - d[6]) * s, (d[3] - d[1]) * s, 0.25 / s
        if d[0] > d[4] and d[0] > d[8]:
            s = 2.0 * math.sqrt(1.0 + d[0] - d[4] - d[8])
            return 0.25 * s, (d[1] + d[3]) / s, (d[2] + d[6]) / s, (d[7] - d[5]) / s
        if d[4] > d[8]:
            s = 2.0 * math.sqrt(1.0 + d[4] - d[0] - d[8])
            return (d[1] + d[3]) / s, 0.25 * s, (d[5] + d[7]) / s, (d[2] - d[6]) / s
        s = 2.0 * math.sqrt(1.0 + d[8] - d[0] - d[4])
        return (d[2] + d[6]) / s, (d[5] + d[7]) / s, 0.25 * s, (d[3] - d[1]) / s

    def GetRotAngle(self, eps: float = epsilon) -> tuple[float, Vector]:
        d = self._d
        if abs(d[1] - d[3]) < eps and abs(d[2] - d[6]) < eps and abs(d[5] - d[7]) < eps:
            e2 = eps * 10
            if (
                abs(d[1] + d[3]) < e2
                and abs(d[2] + d[6]) < e2
                and abs(d[5] + d[7]) < e2
                and abs(d[0] + d[4] + d[8] - 3) < e2
            ):
                return 0.0, Vector._raw(0.0, 0.0, 1.0)
            xx, yy, zz = (d[0] + 1) / 2, (d[4] + 1) / 2, (d[8] + 1) / 2
            xy, xz, yz = (d[1] + d[3]) / 4, (d[2] + d[6]) / 4, (d[5] + d[7]) / 4
            if xx > yy and xx > zz:
                x = math.sqrt(xx)
                y, z = xy / x, xz / x
            elif yy > zz:
                y = math.sqrt(yy)
                x, z = xy / y, yz / y
            else:
                z = math.sqrt(zz)
                x, y = xz / z, yz / z
            return math.pi, Vector._raw(x, y, z)
        f = (d[0] + d[4] + d[8] - 1) / 2
        x, y, z = d[7] - d[5], d[2] - d[6], d[3] - d[1]
        axis = Vector._raw(x, y, z)
        axis.Normalize()
        return math.atan2(math.sqrt(x * x + y * y + z * z) / 2, f), axis

    def GetRot(self) -> Vector:
        angle, axis = self.GetRotAngle()
        return axis * angle

    def UnitX(self) -> Vector:
        return Vector._raw(self._d[0], self._d[3], self._d[6])

    def UnitY(self) -> Vector:
        return Vector._raw(self._d[1], self._d[4], self._d[7])

    def UnitZ(self) -> Vector:
        return Vector._raw(self._d[2], self._d[5], self._d[8])

    def DoRotX(self, angle: float) -> None:
        self._d = (self * Rotation.RotX(angle))._d

    def DoRotY(self, angle: float) -> None:
        self._d = (self * Rotation.RotY(angle))._d

    def DoRotZ(self, angle: float) -> None:
        self._d = (self * Rotation.RotZ(angle))._d

    def SetInverse(self) -> None:
        self._d = self.Inverse()._d

    def Inverse(self, arg: Any = None) -> Any:
        d = self._d
        if arg is None:
            return Rotation._raw([d[0], d[3], d[6], d[1], d[4], d[7], d[2], d[5], d[8]])
        if isinstance(arg, Vector):
            v = arg._d
            return Vector._raw(
                d[0] * v[0] + d[3] * v[1] + d[6] * v[2],
                d[1] * v[0] + d[4] * v[1] + d[7] * v[2],
                d[2] * v[0] + d[5] * v[1] + d[8] * v[2],
            )
        if isinstance(arg, Twist):
            return Twist(self.Inverse(arg.vel), self.Inverse(arg.rot))
        if isinstance(arg, Wrench):
            return Wrench(self.Inverse(arg.force), self.Inverse(arg.torque))
        raise TypeError("Rotation.Inverse(): argument did not match any overloaded call")

    def __mul__(self, o: Any) -> Any:
        a = self._d
        if isinstance(o, Vector):
            v = o._d
            return Vector._raw(
                a[0] * v[0] + a[1] * v[1] + a[2] * v[2],
                a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
                a[6] * v[0] + a[7] * v[1] + a[8] * v[2],
            )
        if isinstance(o, Rotation):
            b = o._d
            return Rotation._raw(
                [
                    a[0] * b[0] + a[1] * b[3] + a[2] * b[6],
                    a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
                    a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
                    a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
                    a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
                    a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
                    a[6] * b[0] + a[7] * b[3] + a[8] * b[6],
                    a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
                    a[6] * b[2] + a[7] * b[5] + a[8] * b[8],
                ]
            )
        if isinstance(o, Twist):
            return Twist(self * o.vel, self * o.rot)
        if isinstance(o, Wrench):
            return Wrench(self * o.force, self * o.torque)
        return NotImplemented

    def __call__(self, i: int, j: int) -> float:
        return self[i, j]

    def __eq__(self, o: object) -> bool:
        return isinstance(o, Rotation) and Equal(self, o)

    def __ne__(self, o: object) -> bool:
        return not self == o

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        d = self._d
        rows = [",".join(_g(v) for v in d[i : i + 3]) for i in (0, 3, 6)]
        return "[" + ";\n ".join(rows) + "]"

    __str__ = __repr__

    def __reduce__(self) -> tuple[Any, ...]:
        return (Rotation, tuple(self._d))

    def __copy__(self) -> Rotation:
        return Rotation(self)

    def __deepcopy__(self, memo: Any) -> Rotation:
        return Rotation(self)


def _pair(ij: Any, imax: int, jmax: int, what: str) -> tuple[int, int]:
    try:
        i, j = ij
    except (TypeError, ValueError):
        raise IndexError(f"{what} index out of range") from None
    if not isinstance(i, int) or not isinstance(j, int) or not (0 <= i <= imax and 0 <= j <= jmax):
        raise IndexError(f"{what} index out of range")
    return i, j


class Frame:
    """A rotation ``M`` and a position ``p``: the pose of a frame in another."""

    __slots__ = ("M", "p")
    M: Rotation
    p: Vector

    def __init__(self, *args: Any) -> None:
        M, p = Rotation(), Vector()
        if len(args) == 1 and isinstance(args[0], Frame):
            M, p = Rotation(args[0].M), Vector(args[0].p)
        elif len(args) == 1 and isinstance(args[0], Rotation):
            M = Rotation(args[0])
        elif len(args) == 1 and isinstance(args[0], Vector):
            p = Vector(args[0])
        elif len(args) == 2 and isinstance(args[0], Rotation) and isinstance(args[1], Vector):
            M, p = Rotation(args[0]), Vector(args[1])
        elif args:
            raise TypeError("Frame(): arguments did not match any overloaded call")
        self.M, self.p = M, p

    @staticmethod
    def Identity() -> Frame:
        return Frame()

    @staticmethod
    def DH(a: float, alpha: float, d: float, theta: float) -> Frame:
        ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
        return Frame(
            Rotation(ct, -st * ca, st * sa, st, ct * ca, -ct * sa, 0, sa, ca),
            Vector(a * ct, a * st, d),
        )

    @staticmethod
    def DH_Craig1989(a: float, alpha: float, d: float, theta: float) -> Frame:
        ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
        return Frame(
            Rotation(ct, -st, 0, st * ca, ct * ca, -sa, st * sa, ct * sa, ca),
            Vector(a, -sa * d, ca * d),
        )

    def Integrate(self, twist: Twist, frequency: float) -> Frame:
        n = twist.rot.Norm() / frequency
        if n < epsilon:
            return Frame(self.M, self.p + twist.vel * (1.0 / frequency))
        return Frame(Rotation.Rot(twist.rot, n) * self.M, self.p + twist.vel * (1.0 / frequency))

    def Inverse(self, arg: Any = None) -> Any:
        if arg is None:
            inv = self.M.Inverse()
            return Frame(inv, -(inv * self.p))
        if isinstance(arg, Vector):
            return self.M.Inverse(arg - self.p)
        if isinstance(arg, Twist):
            rot = self.M.Inverse(arg.rot)
            return Twist(self.M.Inverse(arg.vel - self.p * arg.rot), rot)
        if isinstance(arg, Wrench):
            return Wrench(self.M.Inverse(arg.force), self.M.Inverse(arg.torque - self.p * arg.force))
        raise TypeError("Frame.Inverse(): argument did not match any overloaded call")

    def __getitem__(self, ij: tuple[int, int]) -> float:
        i, j = _pair(ij, 2, 3, "Frame")
        return self.p[i] if j == 3 else self.M[i, j]

    def __setitem__(self, ij: tuple[int, int], value: float) -> None:
        i, j = _pair(ij, 2, 3, "Frame")
        if j == 3:
            self.p[i] = value
        else:
            self.M[i, j] = value

    def __mul__(self, o: Any) -> Any:
        if isinstance(o, Frame):
            return Frame(self.M * o.M, self.M * o.p + self.p)
        if isinstance(o, Vector):
            return self.M * o + self.p
        if isinstance(o, Twist):
            rot = self.M * o.rot
            return Twist(self.M * o.vel + self.p * rot, rot)
        if isinstance(o, Wrench):
            force = self.M * o.force
            return Wrench(force, self.M * o.torque + self.p * force)
        return NotImplemented

    def __eq__(self, o: object) -> bool:
        return isinstance(o, Frame) and Equal(self, o)

    def __ne__(self, o: object) -> bool:
        return not self == o

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"[{self.M!r}\n{self.p!r}]"

    __str__ = __repr__

    def __reduce__(self) -> tuple[Any, ...]:
        return (Frame, (self.M, self.p))

    def __copy__(self) -> Frame:
        return Frame(self)

    def __deepcopy__(self, memo: Any) -> Frame:
        return Frame(self)


class _Screw:
    """A pair of vectors indexed 0..5 (Twist: vel, rot; Wrench: force, torque)."""

    __slots__ = ("_a", "_b")
    _a: Vector
    _b: Vector
    _names = ("", "")

    def __init__(self, *args: Any) -> None:
        if not args:
            a, b = Vector(), Vector()
        elif len(args) == 1 and isinstance(args[0], type(self)):
            a, b = Vector(args[0]._a), Vector(args[0]._b)
        elif len(args) == 2 and all(isinstance(v, Vector) for v in args):
            a, b = Vector(args[0]), Vector(args[1])
        else:
            raise TypeError(f"{type(self).__name__}(): arguments did not match any overloaded call")
        self._a, self._b = a, b

    def __getitem__(self, i: int) -> float:
        if not isinstance(i, int) or i < 0 or i > 5:
            raise IndexError(f"{type(self).__name__} index out of range")
        return self._a[i] if i < 3 else self._b[i - 3]

    def __setitem__(self, i: int, value: float) -> None:
        if not isinstance(i, int) or i < 0 or i > 5:
            raise IndexError(f"{type(self).__name__} index out of range")
        if i < 3:
            self._a[i] = value
        else:
            self._b[i - 3] = value

    def ReverseSign(self) -> None:
        self._a.ReverseSign()
        self._b.ReverseSign()

    def __add__(self, o: Any) -> Any:
        if type(o) is not type(self):
            return NotImplemented
        return type(self)(self._a + o._a, self._b + o._b)

    def __sub__(self, o: Any) -> Any:
        if type(o) is not type(self):
            return NotImplemented
        return type(self)(self._a - o._a, self._b - o._b)

    def __neg__(self) -> Any:
        return type(self)(-self._a, -self._b)

    def __mul__(self, o: Any) -> Any:
        if isinstance(o, (int, float)) and not isinstance(o, bool):
            return type(self)(self._a * o, self._b * o)
        return NotImplemented

    __rmul__ = __mul__

    def __truediv__(self, o: Any) -> Any:
        if isinstance(o, (int, float)) and not isinstance(o, bool):
            return type(self)(self._a / o, self._b / o)
        return NotImplemented

    def __eq__(self, o: object) -> bool:
        return type(o) is type(self) and Equal(self, o)

    def __ne__(self, o: object) -> bool:
        return not self == o

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return "[" + ",".join(_g(v) for v in (*self._a._d, *self._b._d)) + "]"

    __str__ = __repr__

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self._a, self._b))

    def __copy__(self) -> Any:
        return type(self)(self)

    def __deepcopy__(self, memo: Any) -> Any:
        return type(self)(self)


class Twist(_Screw):
    """A velocity screw: linear ``vel`` and angular ``rot``."""

    __slots__ = ()

    @property
    def vel(self) -> Vector:
        return self._a

    @vel.setter
    def vel(self, v: Vector) -> None:
        self._a = Vector(v)

    @property
    def rot(self) -> Vector:
        return self._b

    @rot.setter
    def rot(self, v: Vector) -> None:
        self._b = Vector(v)

    @staticmethod
    def Zero() -> Twist:
        return Twist()

    def RefPoint(self, v: Vector) -> Twist:
        return Twist(self._a + self._b * v, self._b)


class Wrench(_Screw):
    """A force screw: ``force`` and ``torque``."""

    __slots__ = ()

    @property
    def force(self) -> Vector:
        return self._a

    @force.setter
    def force(self, v: Vector) -> None:
        self._a = Vector(v)

    @property
    def torque(self) -> Vector:
        return self._b

    @torque.setter
    def torque(self, v: Vector) -> None:
        self._b = Vector(v)

    @staticmethod
    def Zero() -> Wrench:
        return Wrench()

    def RefPoint(self, v: Vector) -> Wrench:
        return Wrench(self._a, self._b + self._a * v)


def dot(a: Any, b: Any) -> float:
    """Scalar product of two vectors, or the power of a Twist and a Wrench."""
    if isinstance(a, Vector) and isinstance(b, Vector):
        return a._d[0] * b._d[0] + a._d[1] * b._d[1] + a._d[2] * b._d[2]
    if isinstance(a, Twist) and isinstance(b, Wrench):
        return dot(a.rot, b.torque) + dot(a.vel, b.force)
    if isinstance(a, Wrench) and isinstance(b, Twist):
        return dot(b, a)
    raise TypeError("dot(): arguments did not match any overloaded call")


def Equal(a: Any, b: Any, eps: float = epsilon) -> bool:
    """KDL's Equal: every component within ``eps``."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) < eps
    if isinstance(a, Vector) and isinstance(b, Vector):
        return all(abs(x - y) < eps for x, y in zip(a._d, b._d, strict=True))
    if isinstance(a, Rotation) and isinstance(b, Rotation):
        return all(abs(x - y) < eps for x, y in zip(a._d, b._d, strict=True))
    if isinstance(a, Frame) and isinstance(b, Frame):
        return Equal(a.M, b.M, eps) and Equal(a.p, b.p, eps)
    if isinstance(a, _Screw) and type(a) is type(b):
        return Equal(a._a, b._a, eps) and Equal(a._b, b._b, eps)
    raise TypeError("Equal(): arguments did not match any overloaded call")


def diff(a: Any, b: Any, dt: float = 1.0) -> Any:
    """The velocity that takes ``a`` to ``b`` in ``dt`` (KDL's diff)."""
    if isinstance(a, Vector) and isinstance(b, Vector):
        return (b - a) / dt
    if isinstance(a, Rotation) and isinstance(b, Rotation):
        return a * (a.Inverse() * b).GetRot() / dt
    if isinstance(a, Frame) and isinstance(b, Frame):
        return Twist(diff(a.p, b.p, dt), diff(a.M, b.M, dt))
    if isinstance(a, _Screw) and type(a) is type(b):
        return type(a)(diff(a._a, b._a, dt), diff(a._b, b._b, dt))
    raise TypeError("diff(): arguments did not match any overloaded call")


def _rot_vector(v: Vector) -> Rotation:
    angle = v.Norm()
    if angle < _SMALL:
        return Rotation()
    return Rotation.Rot2(v / angle, angle)


def addDelta(a: Any, da: Any, dt: float = 1.0) -> Any:
    """``a`` moved by the velocity ``da`` during ``dt`` (KDL's addDelta)."""
    if isinstance(a, Vector) and isinstance(da, Vector):
        return a + da * dt
    if isinstance(a, Rotation) and isinstance(da, Vector):
        return a * _rot_vector(a.Inverse(da) * dt)
    if isinstance(a, Frame) and isinstance(da, Twist):
        return Frame(addDelta(a.M, da.rot, dt), addDelta(a.p, da.vel, dt))
    if isinstance(a, _Screw) and type(a) is type(da):
        return type(a)(addDelta(a._a, da._a, dt), addDelta(a._b, da._b, dt))
    raise TypeError("addDelta(): arguments did not match any overloaded call")


def SetToZero(v: Any) -> None:
    """Zero a Vector, Twist or Wrench in place."""
    if isinstance(v, Vector):
        v._d = [0.0, 0.0, 0.0]
    elif isinstance(v, _Screw):
        SetToZero(v._a)
        SetToZero(v._b)
    else:
        raise TypeError("SetToZero(): argument did not match any overloaded call")


def changeRefPoint(screw: Any, v_base_AB: Vector) -> Any:
    """A Twist or Wrench with its reference point moved by ``v_base_AB``."""
    return screw.RefPoint(v_base_AB)


def changeBase(arg: Any, rotation: Rotation) -> Any:
    """A Vector, Twist or Wrench expressed in another base: ``rotation * arg``."""
    return rotation * arg
