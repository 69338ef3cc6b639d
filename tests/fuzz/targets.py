"""Fuzz targets: every parser of untrusted input, fed mutated valid inputs.

A target is a function of ``bytes`` that parses them as the system would (a .msg text, a connection
header, a TCPROS stream, an XML-RPC body, a launch file, a bag, a map, a world, a gateway message)
and may raise only its documented error (:class:`ninjemys.errors.NinjemysError` and the subclasses
each parser names). Anything else escaping (IndexError, KeyError, RecursionError, UnicodeError,
MemoryError...) is a bug: the message that reaches the user would not say what was wrong and where.

Inputs are made by :class:`Mutator` from each target's valid seeds (bit flips, byte changes,
inserted and deleted runs, duplicated runs, splices of two seeds, truncations, and "interesting"
integers such as 0xFFFFFFFF over length fields), deterministically from a seed, so a failure is
reproducible by its index.
"""

from __future__ import annotations

import io
import json
import random
import struct
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import NinjemysError

INTERESTING = (b"\xff\xff\xff\xff", b"\xff\xff\xff\x7f", b"\x00\x00\x00\x80", b"\x00\x00\x00\x00", b"\x01\x00\x00\x00",
               b"\x00\x00\x10\x00", b"\xfe\xff\xff\xff")  # fmt: skip
TOKENS = (b"<", b">", b"</", b"/>", b'"', b"=", b"$(", b")", b"[", b"]", b"{", b"}", b":", b"\n", b"\x00", b"#",
          b"---", b"\xff", b"\xc3", b"&", b";", b"'", b"\\", b"%")  # fmt: skip


class Mutator:
    """Deterministic mutations of seed inputs."""

    def __init__(self, seeds: list[bytes], seed: int = 0) -> None:
        self.seeds = [s for s in seeds if s] or [b""]
        self.rng = random.Random(seed)

    def next(self) -> bytes:
        rng = self.rng
        data = bytearray(rng.choice(self.seeds))
        for _ in range(rng.choice((1, 1, 1, 2, 3, 5, 8))):
            op = rng.randrange(9)
            n = len(data)
            if op == 0 and n:  # flip a bit
                i = rng.randrange(n)
                data[i] ^= 1 << rng.randrange(8)
            elif op == 1 and n:  # set a byte
                data[rng.randrange(n)] = rng.randrange(256)
            elif op == 2:  # insert random bytes
                i = rng.randrange(n + 1)
                data[i:i] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 9)))
            elif op == 3 and n:  # delete a run
                i = rng.randrange(n)
                del data[i : i + rng.randrange(1, 33)]
            elif op == 4 and n:  # duplicate a run
                i = rng.randrange(n)
                run = data[i : i + rng.randrange(1, 65)]
                j = rng.randrange(n + 1)
                data[j:j] = run * rng.choice((1, 2, 16))
            elif op == 5:  # splice with another seed
                other = rng.choice(self.seeds)
                i, j = rng.randrange(n + 1), rng.randrange(len(other) + 1)
                data = data[:i] + other[j:]
            elif op == 6 and n:  # truncate
                del data[rng.randrange(n) :]
            elif op == 7 and n >= 4:  # an interesting integer over 4 bytes
                i = rng.randrange(n - 3)
                data[i : i + 4] = rng.choice(INTERESTING)
            elif op == 8:  # a syntax token
                i = rng.randrange(n + 1)
                data[i:i] = rng.choice(TOKENS)
        return bytes(data)


@dataclass
class Target:
    name: str
    run: Callable[[bytes], object]
    seeds: list[bytes]
    allowed: tuple[type[BaseException], ...] = (NinjemysError,)
    #: work on a file: the target writes its input to a temporary path first
    notes: str = field(default="")


# -- message definitions -------------------------------------------------------------------------


def _idl_seeds() -> list[bytes]:
    from ninjemys.idl.search import SHIPPED_ROOT

    root = Path(SHIPPED_ROOT)
    files = sorted(root.glob("*/msg/*.msg"))[:40] + sorted(root.glob("*/srv/*.srv"))[:20]
    files += sorted(root.glob("*/action/*.action"))
    return [f.read_bytes() for f in files]


def _idl(data: bytes) -> None:
    """A .msg, .srv or .action file of a package, as catkin_make and the loader read it."""
    from ninjemys.idl.parser import parse_file

    suffix = (".msg", ".srv", ".action")[data[0] % 3 if data else 0]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"Fuzz{suffix}"
        path.write_bytes(data)
        parse_file(path, "fuzz")


# -- TCPROS ----------------------------------------------------------------------------------------


def _header_seeds() -> list[bytes]:
    from ninjemys.wire.headers import encode_header

    return [
        encode_header(
            {
                "callerid": "/talker",
                "topic": "/chatter",
                "type": "std_msgs/String",
                "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
                "message_definition": "string data\n",
                "latching": "0",
            }
        ),  # fmt: skip
        encode_header({"callerid": "/c", "service": "/add_two_ints", "md5sum": "*", "probe": "1"}),
        encode_header({"error": "no such topic"}),
    ]


def _header(data: bytes) -> None:
    from ninjemys.wire.headers import decode_header, header_length

    if len(data) >= 4:
        header_length(data[:4])
    decode_header(data[4:])


def _frames(data: bytes) -> None:
    """A TCPROS stream cut into receives of varying sizes, as a subscriber reads it."""
    from ninjemys.wire.tcpros import FrameReader

    reader = FrameReader(size=4096, limit=1 << 20)
    pos, step = 0, 1
    while pos < len(data):
        view = reader.buffer()
        n = min(len(view), step, len(data) - pos)
        view[:n] = data[pos : pos + n]
        reader.commit(n)
        pos += n
        step = step * 3 % 1021 + 1


def _frame_seeds() -> list[bytes]:
    from ninjemys.wire.tcpros import frame

    return [
        b"".join(frame(bytes(range(k % 256)) * (k // 50 + 1)) for k in (0, 5, 200, 3000)),
        frame(b"x" * 5000),
    ]


# -- XML-RPC ---------------------------------------------------------------------------------------


def _xmlrpc_seeds() -> list[bytes]:
    from ninjemys.wire.xmlrpc import dump_call, dump_fault, dump_response, http_request

    call = dump_call("registerPublisher", ("/talker", "/chatter", "std_msgs/String", "http://h:1/"))
    nested = dump_response([1, "ok", [["/a", ["/n1", "/n2"]], {"k": 1.5, "b": True, "n": -3}]])
    return [call, nested, dump_fault(1, "no"), http_request("localhost", 11311, call)]


def _xmlrpc(data: bytes) -> None:
    from ninjemys.wire.xmlrpc import HttpRequestParser, parse_call, parse_response

    if data.startswith(b"POST"):
        HttpRequestParser().feed(data)
    elif b"methodCall" in data[:200]:
        parse_call(data)
    else:
        parse_response(data)


# -- launch files --------------------------------------------------------------------------------


_LAUNCH = b"""<launch>
  <arg name="robot" default="puzzlebot"/>
  <arg name="gui" default="true"/>
  <param name="robot_description" value="$(arg robot)"/>
  <rosparam>{a: 1, b: [1, 2], c: {d: x}}</rosparam>
  <group ns="$(arg robot)" if="$(arg gui)">
    <node pkg="turtlesim" type="turtlesim_node" name="sim" args="--x 1" respawn="true">
      <remap from="a" to="b"/><param name="rate" type="double" value="$(eval 2 * 5)"/>
    </node>
  </group>
  <include file="$(find rospy_tutorials)/001_talker_listener/talker_listener.launch" unless="$(arg gui)"/>
  <machine name="m" address="localhost"/>
  <test test-name="t" pkg="p" type="t.py"/>
</launch>
"""


def _launch(data: bytes) -> None:
    """A launch file as roslaunch reads it (bytes from the file system)."""
    from ninjemys.launch.xml import load_launch

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.launch"
        path.write_bytes(data)
        load_launch([path], env={"ROS_MASTER_URI": "http://localhost:11311"})


# -- bags, maps, worlds ----------------------------------------------------------------------------


def _bag_seeds() -> list[bytes]:
    from ninjemys.bag.writer import BagWriter

    header = {"type": b"std_msgs/String", "md5sum": b"992ce8a1687cec8c8bd883ec73ca41d1",
              "message_definition": b"string data\n", "callerid": b"/talker", "latching": b"0"}  # fmt: skip
    out = []
    for compression in ("none", "bz2"):
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "seed.bag"
            with BagWriter(path, compression=compression, chunk_threshold=256) as writer:
                conn = writer.connection("/chatter", header)
                for i in range(12):
                    text = f"hello {i}".encode()
                    writer.write(conn, 1_000_000_000 * (i + 1), struct.pack("<I", len(text)) + text)
            out.append(path.read_bytes())
    return out


def _bag(data: bytes) -> None:
    from ninjemys.bag.reader import BagReader

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.bag"
        path.write_bytes(data)
        reader = BagReader(path)
        try:
            for _ in reader.read():
                pass
        finally:
            reader.close()


_MAP_YAML = b"image: map.pgm\nresolution: 0.05\norigin: [-1.0, -2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"


def _map_seeds() -> list[bytes]:
    pgm = b"P5\n# ninjemys\n4 3\n255\n" + bytes([0, 255, 205, 100] * 3)
    return [_MAP_YAML + b"\x00MAP\x00" + pgm]


def _map(data: bytes) -> None:
    from ninjemys.maps.mapfile import load_map

    yaml_part, _, image = data.partition(b"\x00MAP\x00")
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "map.pgm").write_bytes(image)
        (Path(tmp) / "map.yaml").write_bytes(yaml_part)
        load_map(Path(tmp) / "map.yaml")


def _world_seeds() -> list[bytes]:
    from ninjemys.sim.worlds import world_path

    return [world_path(name).read_bytes() for name in ("square", "maze", "office", "two_robots")]


def _world(data: bytes) -> None:
    from ninjemys.sim.world2d import load_world

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "fuzz.yaml"
        path.write_bytes(data)
        load_world(path)


# -- the gateway -------------------------------------------------------------------------------------


def _gateway_seeds() -> list[bytes]:
    msgs = [
        {
            "op": "publish",
            "topic": "/cmd_vel",
            "msg": {"linear": {"x": 0.5, "y": 0, "z": 0}, "angular": {"z": 1}},
        },
        {
            "op": "publish",
            "topic": "/image",
            "msg": {
                "header": {"stamp": {"secs": 1, "nsecs": 2}, "frame_id": "c"},
                "height": 1,
                "width": 2,
                "encoding": "mono8",
                "step": 2,
                "data": "AAE=",
            },
        },  # fmt: skip
        {"op": "publish", "topic": "/joy", "msg": {"axes": [0.1, -1], "buttons": [0, 1]}},
    ]
    return [json.dumps(m).encode() for m in msgs]


_GATEWAY_TYPES = {"/cmd_vel": "geometry_msgs/Twist", "/image": "sensor_msgs/Image", "/joy": "sensor_msgs/Joy"}


def _gateway(data: bytes) -> None:
    """A rosbridge ``publish`` op's message turned into a ROS message (what a browser sends)."""
    from ninjemys.bridge.convert import from_value
    from ninjemys.idl.loader import get_message_class

    try:
        op = json.loads(data)
    except (ValueError, RecursionError):
        return  # not JSON: the session answers with a status message before any conversion
    if not isinstance(op, dict):
        return
    type_name = _GATEWAY_TYPES.get(str(op.get("topic")), "geometry_msgs/Twist")
    msg = from_value(get_message_class(type_name), op.get("msg"), where="msg")
    msg.serialize(io.BytesIO())


def targets() -> list[Target]:
    """Every target, with its seeds (built on first use)."""
    return [
        Target("idl", _idl, _idl_seeds()),
        Target("tcpros_header", _header, _header_seeds()),
        Target("tcpros_frames", _frames, _frame_seeds()),
        Target("xmlrpc", _xmlrpc, _xmlrpc_seeds()),
        Target("launch_xml", _launch, [_LAUNCH]),
        Target("bag", _bag, _bag_seeds()),
        Target("map", _map, _map_seeds()),
        Target("world", _world, _world_seeds()),
        Target("gateway", _gateway, _gateway_seeds()),
    ]


def check(target: Target, data: bytes) -> BaseException | None:
    """The unexpected exception ``data`` raises in ``target`` (None when it parses or fails cleanly)."""
    try:
        target.run(data)
    except target.allowed:
        return None
    except Exception as exc:  # noqa: BLE001 - the point: anything else is a finding
        return exc
    return None
