"""A JointState stream's transforms computed by a function generated once per list of joint names.

robot_state_publisher's CPU is per message, and in a joint state stream only the numbers change: the
names (and so which joints move, which mimic joints follow, and every frame name of the TFMessage) are
the same message after message. A :class:`TfPlan` is made once per distinct list of names. It writes
the Python source of one straight-line function for that list, with every constant of the robot in
it as a literal, and compiles it; per message that function takes the positions as they were unpacked
from the received bytes and, per moving joint:

* its value: ``position[source] * a + b`` (a mimic joint: its leader's position, multiplier, offset);
* a revolute or continuous joint: rotation ``cos(value/2) * O + sin(value/2) * B``, O the origin's
  quaternion and B its product with the axis (the origin times the axis-angle quaternion in 8 products
  and 4 sums), with the sign KDL's GetQuaternion gives (the branch component made positive), and the
  origin's translation;
* a prismatic one: the origin's translation plus ``value`` times the rotated axis, the origin's rotation;

and packs the whole TFMessage with one precompiled ``struct`` (the frame names are constant arguments,
seq 0 as tf2 sends). Why generated: the node wakes 50 times a second with its caches cold, and then
each bytecode costs several times what it costs in a loop; a loop over rows of constants spends most
of its bytecodes unpacking the rows. The straight-line function runs only the arithmetic (about half
the bytecodes), and is cheaper than numpy for a robot of a few dozen joints, whose per-call overhead
(~1-3 us per array operation, more when cold) outweighs the arithmetic of 20 rows.

KDL's sign (:func:`ninjemys.robot.kinematics.kdl_sign`, written inline) is one comparison when
``w > 0.5``, a few more otherwise.

The order of the transforms, the mimic semantics and the numbers (to rounding, ~1e-16) are those of
:meth:`ninjemys.robot.state_publisher.StatePublisher.on_joint_state`'s general path, which handles
what a plan does not (a list of names with duplicates).
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Sequence

from ninjemys.robot.kinematics import Joint, apply_rotation, quaternion

_MOVING = frozenset(("revolute", "continuous", "prismatic"))


class TfPlan:
    """The transforms of one list of joint names (see the module docstring).

    ``message(positions, secs, nsecs) -> bytes`` is the serialized TFMessage; ``positions`` are the
    message's, in its order, after ``skip`` leading items (the unpacked position count, say). With
    ``framed`` it is the whole TCPROS frame: the length (constant for a plan) packed in front."""

    def __init__(
        self,
        names: Sequence[str],
        joints: dict[str, Joint],
        mimics: dict[str, list[Joint]],
        frames: Callable[[Joint], bytes],
        skip: int = 0,
        framed: bool = False,
    ) -> None:
        #: the names the robot has, for the throttle's bookkeeping
        self.known = [n for n in names if n in joints]
        index = {n: i + skip for i, n in enumerate(names)}
        values: dict[str, tuple[int, float, float]] = {n: (index[n], 1.0, 0.0) for n in self.known}
        moving = [joints[n] for n in values if joints[n].type in _MOVING]
        for name in list(values) if mimics else ():
            for mimic in mimics.get(name, ()):
                assert mimic.mimic is not None
                src, a, b = values[name]
                m = mimic.mimic
                values[mimic.name] = (src, a * m.multiplier, b * m.multiplier + m.offset)
                if mimic.type != "fixed":
                    moving.append(mimic)
        self.count = len(moving)
        self.source = _Source()
        self.message: Callable[[Sequence[float], int, int], bytes] = self._compile(
            moving, values, frames, framed
        )

    def _compile(
        self,
        moving: list[Joint],
        values: dict[str, tuple[int, float, float]],
        frames: Callable[[Joint], bytes],
        framed: bool,
    ) -> Callable[[Sequence[float], int, int], bytes]:
        src = self.source
        fmt = ["<I"]
        body: list[str] = []
        args = [str(self.count)]
        for k, joint in enumerate(moving):
            index, a, b = values[joint.name]
            frame = frames(joint)
            fmt.append(f"III{len(frame)}s7d")
            ox, oy, oz, ow = quaternion(joint.rotation)
            x0, y0, z0 = joint.xyz
            lit = src.literal
            if joint.type == "prismatic":
                dx, dy, dz = apply_rotation(joint.rotation, joint.axis)
                v = f"v{k}"  # every value lives until the one pack at the end: a name per joint
                body.append(f"{v} = p[{index}]{_affine(a, b, lit)}")
                pose = [f"{lit(x0)} + {lit(dx)} * {v}", f"{lit(y0)} + {lit(dy)} * {v}"]
                pose += [f"{lit(z0)} + {lit(dz)} * {v}", lit(ox), lit(oy), lit(oz), lit(ow)]
            else:
                if (
                    joint.type not in _MOVING
                ):  # a floating or planar mimic joint stays at its origin, as in KDL
                    a = b = 0.0
                ax, ay, az = joint.axis
                bx, by = ow * ax + oy * az - oz * ay, ow * ay - ox * az + oz * ax
                bz, bw = ow * az + ox * ay - oy * ax, -(ox * ax + oy * ay + oz * az)
                q = [f"x{k}", f"y{k}", f"z{k}", f"w{k}"]
                body += [
                    f"h = p[{index}]{_affine(a * 0.5, b * 0.5, lit)}",
                    "c = cos(h); s = sin(h)",
                    f"{q[0]} = c * {lit(ox)} + s * {lit(bx)}; {q[1]} = c * {lit(oy)} + s * {lit(by)}",
                    f"{q[2]} = c * {lit(oz)} + s * {lit(bz)}; {q[3]} = c * {lit(ow)} + s * {lit(bw)}",
                    *_sign(*q),
                ]
                pose = [lit(x0), lit(y0), lit(z0), *q]
            args += ["0", "secs", "nsecs", src.constant(frame), *pose]
        if framed:
            fmt[0] = "<II"
            args.insert(0, str(struct.calcsize("".join(fmt)) - 4))
        src.names["pack"] = struct.Struct("".join(fmt)).pack
        # the functions as defaults: local names, cheaper than globals on every use
        lines = [
            "def message(p, secs, nsecs, cos=cos, sin=sin, pack=pack):",
            *(f"    {line}" for line in body),
        ]
        lines.append(f"    return pack({', '.join(args)})")
        return src.function("\n".join(lines), "message")


def _affine(a: float, b: float, lit: Callable[[float], str]) -> str:
    """`` * a + b`` as source, without the operations that change nothing (``b == 0``; ``a == 1``)."""
    return ("" if a == 1.0 else f" * {lit(a)}") + (f" + {lit(b)}" if b else "")


def _sign(x: str, y: str, z: str, w: str) -> list[str]:
    """:func:`ninjemys.robot.kinematics.kdl_sign` inline on the named components (a call costs more)."""
    return [
        f"if not {w} > 0.5:",
        f"    if {w} < -0.5 or ({x} < 0.0 if {x} * {x} > {y} * {y} and {x} * {x} > {z} * {z}"
        f" else {y} < 0.0 if {y} * {y} > {z} * {z} else {z} < 0.0):",
        f"        {x} = -{x}; {y} = -{y}; {z} = -{z}; {w} = -{w}",
    ]


class _Source:
    """The generated function's text and the names it uses (constants that are no literals)."""

    def __init__(self) -> None:
        self.names: dict[str, object] = {"cos": math.cos, "sin": math.sin}
        self.text = ""

    def literal(self, value: float) -> str:
        """``value`` as source: its repr (exact for a finite float), else a name bound to it."""
        return repr(value) if math.isfinite(value) else self.constant(value)

    def constant(self, value: object) -> str:
        name = f"k{len(self.names)}"
        self.names[name] = value
        return name

    def function(self, text: str, name: str) -> Callable:
        self.text = text
        exec(compile(text, "<robot_state_publisher plan>", "exec"), self.names)  # noqa: S102
        return self.names[name]  # type: ignore[return-value]
