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

import contextlib
import io
import json
import os
import random
import shutil
import struct
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import NinjemysError

_SCRATCH: list[tempfile.TemporaryDirectory[str]] = []


@contextlib.contextmanager
def _as_files(files: dict[str, bytes]) -> Iterator[Path]:
    """The input written as ``files`` in the run's scratch directory; emptied again after the parse.

    One directory for the whole run, not one per input: making and removing a directory for every
    input cost ~7 ms on the loaded 2-core machine, more than most parses (the short form spent a
    sixth of its time there). Each parse still sees only its own files: everything is removed after it.
    """
    if not _SCRATCH:
        _SCRATCH.append(tempfile.TemporaryDirectory(prefix="ninjemys_fuzz_"))
    root = Path(_SCRATCH[0].name)
    try:
        for name, data in files.items():
            (root / name).write_bytes(data)
        yield root
    finally:
        for entry in os.scandir(root):
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path)
            else:
                os.unlink(entry.path)


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
    with _as_files({f"Fuzz{suffix}": data}) as tmp:
        parse_file(tmp / f"Fuzz{suffix}", "fuzz")


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

    with _as_files({"fuzz.launch": data}) as tmp:
        load_launch([tmp / "fuzz.launch"], env={"ROS_MASTER_URI": "http://localhost:11311"})


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

    with _as_files({"fuzz.bag": data}) as tmp:
        reader = BagReader(tmp / "fuzz.bag")
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
    with _as_files({"map.pgm": image, "map.yaml": yaml_part}) as tmp:
        load_map(tmp / "map.yaml")


def _world_seeds() -> list[bytes]:
    from ninjemys.sim.worlds import world_path

    return [world_path(name).read_bytes() for name in ("square", "maze", "office", "two_robots")]


def _world(data: bytes) -> None:
    from ninjemys.sim.world2d import load_world

    with _as_files({"fuzz.yaml": data}) as tmp:
        load_world(tmp / "fuzz.yaml")


# -- Gazebo worlds (SDF) and mesh files ---------------------------------------------------------------


_SDF_WORLD = b"""<?xml version="1.0"?>
<sdf version="1.6">
  <world name="course">
    <include><uri>model://ground_plane</uri></include>
    <include><uri>model://sun</uri></include>
    <include><uri>model://construction_cone</uri><name>cone</name><pose>1 2 0 0 0 0.3</pose></include>
    <model name="box"><static>true</static><pose>2 0 0.25 0 0 0</pose>
      <link name="link"><pose>0 0 0 0.1 0 0</pose>
        <collision name="c"><geometry><box><size>0.5 1 0.5</size></box></geometry></collision>
        <visual name="v"><geometry><box><size>0.5 1 0.5</size></box></geometry>
          <material><script><name>Gazebo/Red</name></script><diffuse>1 0 0 1</diffuse></material></visual>
      </link>
      <model name="inner"><link name="l"><collision name="c"><geometry><cylinder><radius>0.2</radius>
        <length>1</length></cylinder></geometry></collision></link></model>
    </model>
    <model name="shapes"><link name="l">
      <collision name="s"><geometry><sphere><radius>0.3</radius></sphere></geometry></collision>
      <collision name="p"><geometry><polyline><point>0 0</point><point>1 0</point><point>0 1</point>
        <height>0.5</height></polyline></geometry></collision>
    </link></model>
    <state world_name="course"><model name="box"><pose>3 0 0.25 0 0 0</pose></model></state>
    <actor name="walker"/>
  </world>
</sdf>
"""


def _sdf_world(data: bytes) -> None:
    from ninjemys.sim.sdf import parse_sdf_world

    parse_sdf_world(data, "fuzz.world", env={"HOME": "/nonexistent"}, warn=lambda _m: None)


def _mesh_seeds() -> list[bytes]:
    from ninjemys.sim.sdf import SHIPPED_MODELS

    stl = (SHIPPED_MODELS / "construction_cone" / "meshes" / "cone.stl").read_bytes()
    ascii_stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 1\nendloop\nendfacet\nendsolid t\n"
    dae = (
        b'<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1"><asset>'
        b'<unit meter="0.01"/><up_axis>Y_UP</up_axis></asset><library_geometries><geometry id="g"><mesh>'
        b'<source id="p"><float_array id="a" count="9">0 0 0 1 0 0 0 1 1</float_array></source>'
        b'<vertices id="v"><input semantic="POSITION" source="#p"/></vertices></mesh></geometry>'
        b'</library_geometries><library_visual_scenes><visual_scene id="s"><node><translate>1 2 3</translate>'
        b'<rotate>0 0 1 90</rotate><scale>1 2 1</scale><instance_geometry url="#g"/></node></visual_scene>'
        b"</library_visual_scenes></COLLADA>"
    )
    obj = b"v 0 0 0\nv 1 0 0\nv 0 1 1\nf 1 2 3\nf -1 -2 -3\n"
    return [b"stl" + stl, b"stl" + ascii_stl, b"dae" + dae, b"obj" + obj]


def _mesh(data: bytes) -> None:
    from ninjemys.sim.meshes import load_mesh_parts

    kind = {b"stl": ".stl", b"dae": ".dae", b"obj": ".obj"}.get(data[:3], ".stl")
    with _as_files({f"fuzz{kind}": data[3:]}) as tmp:
        load_mesh_parts(tmp / f"fuzz{kind}")


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


# -- device drivers: what a serial port delivers ------------------------------------------------------


def _rosserial(data: bytes) -> None:
    """A rosserial byte stream cut into reads of varying sizes; each packet's TopicInfo decoded as the
    host decodes a negotiation (the host logs a payload that does not decode and goes on)."""
    from ninjemys.drivers.rosserial_protocol import Frame, FrameReader
    from ninjemys.idl.loader import get_message_class

    info = get_message_class("rosserial_msgs/TopicInfo")
    reader = FrameReader()
    pos, step = 0, 1
    while pos < len(data):
        for item in reader.feed(data[pos : pos + step]):
            if isinstance(item, Frame) and item.topic_id == 0 and item.payload:
                info().deserialize(item.payload)
            elif not isinstance(item, Frame):
                item.log_line()
        pos += step
        step = step * 3 % 97 + 1


def _rosserial_seeds() -> list[bytes]:
    from ninjemys.drivers.rosserial_protocol import frame
    from ninjemys.idl.loader import get_message_class

    ti = get_message_class("rosserial_msgs/TopicInfo")()
    ti.topic_id, ti.topic_name, ti.message_type, ti.md5sum, ti.buffer_size = (
        125,
        "wl",
        "std_msgs/Float32",
        "7" * 32,
        280,
    )
    return [
        frame(0, ti.serialize_to_bytes()) + frame(125, b"\x00\x00\xc0\x3f") + frame(10, bytes(8)),
        b"noise" + frame(7),
    ]


def _rplidar(data: bytes) -> None:
    """An RPLIDAR stream as the node reads it: a descriptor, then standard nodes or express capsules,
    assembled into revolutions and turned into LaserScan fields."""
    from ninjemys.drivers import rplidar_protocol as rp
    from ninjemys.drivers.rplidar_scan import RevolutionAssembler, revolution_to_scan

    if len(data) >= rp.DESCRIPTOR_SIZE:
        try:
            rp.Descriptor.unpack(data[: rp.DESCRIPTOR_SIZE]).check(rp.CMD_SCAN)
        except rp.RplidarError:
            pass
    for decoder in (rp.NodeDecoder(), rp.CapsuleDecoder()):
        assembler = RevolutionAssembler()
        for pos in range(0, len(data), 200):
            for rev in assembler.feed(decoder.feed(data[pos : pos + 200])):
                for compensate in (True, False):
                    revolution_to_scan(rev, compensate, 2, 0.1, False, 16.0)


def _rplidar_seeds() -> list[bytes]:
    from ninjemys.drivers import rplidar_protocol as rp

    nodes = b"".join(rp.pack_node(a * 7.5, 1000 + a, 40, a % 48 == 0) for a in range(100))
    caps = b"".join(
        rp.pack_capsule(c * 30.0, [500.0 + i for i in range(32)], [3] * 32, c == 0) for c in range(14)
    )
    return [rp.Descriptor(5, 1, 0x81).pack() + nodes, rp.Descriptor(84, 1, 0x82).pack() + caps]


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
        Target("sdf_world", _sdf_world, [_SDF_WORLD]),
        Target("mesh", _mesh, _mesh_seeds()),
        Target("rosserial", _rosserial, _rosserial_seeds()),
        Target("rplidar", _rplidar, _rplidar_seeds()),
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
