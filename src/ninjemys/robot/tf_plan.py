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

and packs the whole TFMessage with one precompiled ``struct``. What does not change is one bytes
literal per run of it (the length and count; a transform's frame names with a revolute joint's
translation, or a prismatic joint's rotation), the seq (0, as tf2 sends) pad bytes, and the stamp the
8 bytes received: per transform 6 arguments instead of 11, each a conversion of the ``struct``'s loop
(measured ~20 % of a message's FK and packing). Why generated: the node wakes 50 times a second with its caches cold, and then
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
import re
import struct
from collections.abc import Callable, Sequence

from ninjemys.robot.kinematics import Joint, apply_rotation, quaternion

_MOVING = frozenset(("revolute", "continuous", "prismatic"))
_TRANSLATION = struct.Struct("<3d")
_ROTATION = struct.Struct("<4d")
#: arguments of one generated ``pack`` call (see :func:`_groups`)
_MAX_ARGS = 28


class TfPlan:
    """The transforms of one list of joint names (see the module docstring).

    ``message(positions, stamp) -> bytes`` is the serialized TFMessage; ``positions`` are the
    message's, in its order, after ``skip`` leading items (the unpacked position count, say), and
    ``stamp`` the 8 bytes of a ``time`` (secs, nsecs, little-endian: the JointState's, as received). With
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
        #: the offset of each transform's stamp in a message (see :meth:`segments`)
        self.stamps: list[int] = []
        self.source = _Source()
        self.message: Callable[[Sequence[float], bytes], bytes] = self._compile(
            moving, values, frames, framed
        )

    def _compile(
        self,
        moving: list[Joint],
        values: dict[str, tuple[int, float, float]],
        frames: Callable[[Joint], bytes],
        framed: bool,
    ) -> Callable[[Sequence[float], bytes], bytes]:
        src = self.source
        # what never changes goes into the struct as bytes ('s'), a run of it one argument: the
        # length and count, each transform's frame names with a revolute joint's translation (or a
        # prismatic one's rotation), and the seq (0) as pad bytes; per transform the stamp (8 bytes,
        # as received) and the 4 (or 3) moving floats are the only other arguments
        fmt = ["<"]
        body: list[str] = []
        args: list[str] = []
        stamps: list[int] = []  # where in fmt each transform's seq pad and stamp are
        head = struct.pack("<I", self.count)
        for k, joint in enumerate(moving):
            index, a, b = values[joint.name]
            frame = frames(joint)
            ox, oy, oz, ow = quaternion(joint.rotation)
            x0, y0, z0 = joint.xyz
            lit = src.literal
            if joint.type == "prismatic":
                dx, dy, dz = apply_rotation(joint.rotation, joint.axis)
                v = f"v{k}"  # every value lives until the one pack at the end: a name per joint
                body.append(f"{v} = p[{index}]{_affine(a, b, lit)}")
                _constant(fmt, args, head)
                stamps.append(len(fmt))
                fmt.append(f"4x8s{len(frame)}s3d")
                args += ["stamp", repr(frame)]
                args += [f"{lit(x0)} + {lit(dx)} * {v}", f"{lit(y0)} + {lit(dy)} * {v}"]
                args.append(f"{lit(z0)} + {lit(dz)} * {v}")
                head = _ROTATION.pack(ox, oy, oz, ow)
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
                    f"{q[0]} = {_mix(ox, bx, lit)}; {q[1]} = {_mix(oy, by, lit)}",
                    f"{q[2]} = {_mix(oz, bz, lit)}; {q[3]} = {_mix(ow, bw, lit)}",
                    *_sign(*q),
                ]
                constant = frame + _TRANSLATION.pack(x0, y0, z0)
                _constant(fmt, args, head)
                stamps.append(len(fmt))
                fmt.append(f"4x8s{len(constant)}s4d")
                args += ["stamp", repr(constant), *q]
                head = b""
        _constant(fmt, args, head)
        if framed:  # the length in front, with the count (fmt[1], args[0]): one constant
            first = struct.pack("<II", struct.calcsize("".join(fmt)), self.count)
            fmt[1], args[0] = f"{len(first)}s", repr(first)
        self.stamps = [struct.calcsize("".join(fmt[:i])) + 4 for i in stamps]
        packs = [
            f"{src.constant(struct.Struct(''.join(f)).pack)}({', '.join(a)})" for f, a in _groups(fmt, args)
        ]
        # the functions as defaults: local names, cheaper than globals on every use
        defaults = ", ".join(f"{name}={name}" for name in src.names if name != "__builtins__")
        lines = [f"def message(p, stamp, {defaults}):", *(f"    {line}" for line in body)]
        lines.append(
            f"    return {packs[0]}" if len(packs) == 1 else f"    return b''.join(({', '.join(packs)}))"
        )
        return src.function("\n".join(lines), "message")

    def segments(self, message: bytes) -> list[bytes]:
        """``message`` cut around its stamps: ``stamp.join(segments)`` is the same message with
        another stamp (a stream whose positions have not changed: a robot at rest)."""
        cuts = [0, *(o for offset in self.stamps for o in (offset, offset + 8)), len(message)]
        return [message[cuts[i] : cuts[i + 1]] for i in range(0, len(cuts), 2)]


def _groups(fmt: list[str], args: list[str]) -> list[tuple[list[str], list[str]]]:
    """``fmt`` (its byte order first) and its arguments cut into runs of at most :data:`_MAX_ARGS`
    arguments, each with the byte order, at item boundaries: packed one after the other and joined,
    they are the bytes of the whole (``<`` has no alignment to break). Why: a call with more than
    about 30 arguments is compiled into a list built one append at a time, made a tuple and called
    the slow way (``CALL_FUNCTION_EX``); ~10 % of a plan's instructions for a 20-joint robot."""
    groups: list[tuple[list[str], list[str]]] = []
    items, given = fmt[:1], list[str]()
    rest = iter(args)
    for item in re.findall(r"\d*[a-zA-Z?]", "".join(fmt[1:])):
        code, repeat = item[-1], int(item[:-1] or 1)
        count = 0 if code == "x" else 1 if code in "sp" else repeat
        if len(given) + count > _MAX_ARGS:
            groups.append((items, given))
            items, given = fmt[:1], list[str]()
        items.append(item)
        given += [next(rest) for _ in range(count)]
    groups.append((items, given))
    return groups


def _constant(fmt: list[str], args: list[str], data: bytes) -> None:
    """Constant bytes into the struct: one ``s`` item and its literal (nothing when empty)."""
    if data:
        fmt.append(f"{len(data)}s")
        args.append(repr(data))


def _mix(a: float, b: float, lit: Callable[[float], str]) -> str:
    """``c * a + s * b`` as source, without the terms a zero removes or the products a one does
    (an origin without rotation and an axis along x, y or z, as most URDFs have them: a joint's
    quaternion is then ``(0, 0, s, c)``, 2 assignments instead of 4 sums of 2 products)."""
    terms = [f"{name}" if k == 1.0 else f"-{name}" if k == -1.0 else f"{name} * {lit(k)}"
             for name, k in (("c", a), ("s", b)) if k != 0.0]  # fmt: skip
    return " + ".join(terms) if terms else "0.0"


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
