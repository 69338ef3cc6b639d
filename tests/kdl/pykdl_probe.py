"""Run under either interpreter: random PyKDL computations printed as JSON (the parity tests diff them).

Imports PyKDL and tf_conversions from whatever the interpreter finds, so Debian's C++ PyKDL under
/usr/bin/python3 and ours under the venv produce comparable output.
"""

import json
import math
import random
import sys

import PyKDL as K


def vec(v):
    return [v[0], v[1], v[2]]


def rot(r):
    return [r[i, j] for i in range(3) for j in range(3)]


def frame(f):
    return rot(f.M) + vec(f.p)


def screw(t):
    return [t[i] for i in range(6)]


def main():
    rng = random.Random(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
    out = []

    def u(a=-3.0, b=3.0):
        return rng.uniform(a, b)

    for _ in range(200):
        a, b = K.Vector(u(), u(), u()), K.Vector(u(), u(), u())
        r1 = K.Rotation.RPY(u(), u(), u())
        r2 = K.Rotation.Quaternion(u(), u(), u(), u())
        q = [u(), u(), u(), u()]
        n = math.sqrt(sum(x * x for x in q))
        r3 = K.Rotation.Quaternion(*[x / n for x in q])
        f1, f2 = K.Frame(r1, a), K.Frame(r3, b)
        t = K.Twist(a, b)
        w = K.Wrench(b, a)
        row = {
            "cross": vec(a * b),
            "sum": vec(a + b - a * 2.0 / 3.0),
            "dot": K.dot(a, b),
            "norm": a.Norm(),
            "rpy": rot(r1),
            "quat_raw": rot(r2),
            "getrpy": list(r1.GetRPY()),
            "getrpy3": list(r3.GetRPY()),
            "getquat": list(r1.GetQuaternion()),
            "getquat3": list(r3.GetQuaternion()),
            "zyz": list(r3.GetEulerZYZ()),
            "zyx": list(r3.GetEulerZYX()),
            "eulerzyz": rot(K.Rotation.EulerZYZ(u(), u(), u())),
            "rotx": rot(K.Rotation.RotX(u()) * K.Rotation.RotY(u()) * K.Rotation.RotZ(u())),
            "rot": rot(K.Rotation.Rot(a, u())),
            "getrot": vec(r3.GetRot()),
            "rotangle": r3.GetRotAngle()[0],
            "ff": frame(f1 * f2),
            "finv": frame(f1.Inverse()),
            "fv": vec(f1 * b),
            "finvv": vec(f1.Inverse(b)),
            "ft": screw(f1 * t),
            "fw": screw(f1 * w),
            "finvt": screw(f1.Inverse(t)),
            "rt": screw(r1 * t),
            "refpoint": screw(t.RefPoint(b)) + screw(w.RefPoint(a)),
            "tw": K.dot(t, w),
            "diff": screw(K.diff(f1, f2)),
            "adddelta": frame(K.addDelta(f1, t, 0.1)),
            "dh": frame(K.Frame.DH(u(), u(), u(), u())) + frame(K.Frame.DH_Craig1989(1, 2, 3, 4)),
            "unit": vec(r1.UnitX()) + vec(r1.UnitY()) + vec(r1.UnitZ()),
            "repr": [repr(a), repr(r1), repr(f1), repr(t), str(w)],
        }
        out.append(row)
    errors = []
    for probe in (
        lambda: K.Vector(1, 2, 3)[3],
        lambda: K.Vector(1, 2, 3)[-1],
        lambda: K.Rotation()[3, 0],
        lambda: K.Frame()[0, 4],
        lambda: K.Twist()[6],
        lambda: K.Vector(1, 2),
        lambda: K.Frame(1),
    ):
        try:
            probe()
            errors.append(None)
        except Exception as exc:  # noqa: BLE001 - the probe compares error types
            errors.append(type(exc).__name__)
    special = {
        "eq": [K.Vector(1, 2, 3) == K.Vector(1, 2, 3 + 1e-9), K.Vector(1, 2, 3) == K.Vector(1, 2, 3.1)],
        "ident": repr(K.Frame.Identity()),
        "zero": repr(K.Twist.Zero()) + repr(K.Wrench.Zero()) + repr(K.Vector.Zero()),
        "rot180": list(K.Rotation.RotX(math.pi).GetQuaternion()),
        "rot180b": [K.Rotation.RotY(math.pi).GetRotAngle()[0]]
        + vec(K.Rotation.RotY(math.pi).GetRotAngle()[1]),
        "gimbal": list(K.Rotation.RPY(0.3, math.pi / 2, 0.2).GetRPY()),
        "xyz": [K.Vector(4, 5, 6).x(), K.Vector(4, 5, 6).y(), K.Vector(4, 5, 6).z()],
    }
    print(json.dumps({"rows": out, "errors": errors, "special": special}))


if __name__ == "__main__":
    main()
