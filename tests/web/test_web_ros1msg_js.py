"""The browser's ROS 1 decoder (static/lib/ros1msg.js) against bytes from our Python serializer.

Run under Node.js (the same ES module the pages load): each message is decoded, compared field by
field with the Python message, re-encoded and compared byte for byte.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Duration, Time

NODE = shutil.which("node")
LIB = Path(__file__).parents[2] / "src/ninjemys/web/static/lib/ros1msg.js"
SCRIPT = Path(__file__).parent / "js/ros1msg_roundtrip.mjs"

pytestmark = pytest.mark.skipif(NODE is None, reason="Node.js is not installed")


def _plain(value: Any) -> Any:
    """A Python message as the JS side's plain object (lists for arrays, {secs, nsecs} for times)."""
    if hasattr(value, "__slots__") and hasattr(value, "_slot_types"):
        return {name: _plain(getattr(value, name)) for name in value.__slots__}
    if isinstance(value, Time | Duration):
        return {"secs": value.secs, "nsecs": value.nsecs}
    if isinstance(value, bytes | bytearray):
        return list(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def _close(a: Any, b: Any, where: str = "") -> None:
    if isinstance(a, dict):
        assert set(a) == set(b), where
        for k in a:
            _close(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _close(x, y, f"{where}[{i}]")
    elif isinstance(a, float):
        assert math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-6), f"{where}: {a} != {b}"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def _messages() -> list[Any]:
    M = get_message_class  # noqa: N806
    header = M("std_msgs/Header")(seq=7, stamp=Time(12, 345), frame_id="base_laser")
    scan = M("sensor_msgs/LaserScan")(
        header=header,
        angle_min=-1.5,
        angle_max=1.5,
        angle_increment=0.01,
        range_min=0.1,
        range_max=10.0,
        ranges=[float(i) / 10 for i in range(301)],
        intensities=[],
    )
    cloud = M("sensor_msgs/PointCloud2")(
        header=header,
        height=1,
        width=3,
        fields=[
            M("sensor_msgs/PointField")(name=n, offset=4 * i, datatype=7, count=1)
            for i, n in enumerate("xyz")
        ],
        is_bigendian=False,
        point_step=12,
        row_step=36,
        data=np.arange(9, dtype="<f4").tobytes(),
        is_dense=True,
    )
    grid = M("nav_msgs/OccupancyGrid")(header=header)
    grid.info.resolution = 0.05
    grid.info.width, grid.info.height = 4, 3
    grid.info.origin.orientation.w = 1.0
    grid.data = [0, 100, -1, 50] * 3
    marker = M("visualization_msgs/Marker")(header=header, ns="naïve ✓", id=-3, type=4, action=0)
    marker.lifetime = Duration(-2, 500)
    marker.points = [M("geometry_msgs/Point")(x=1.0, y=2.0, z=3.0)] * 2
    marker.colors = [M("std_msgs/ColorRGBA")(r=1.0, a=0.5)]
    marker.text = "x" * 100
    markers = M("visualization_msgs/MarkerArray")(markers=[marker, marker])
    pose = M("geometry_msgs/PoseWithCovarianceStamped")(header=header)
    pose.pose.covariance = [float(i) for i in range(36)]
    pose.pose.pose.orientation.w = 1.0
    tf = M("tf2_msgs/TFMessage")(
        transforms=[M("geometry_msgs/TransformStamped")(header=header, child_frame_id="a")]
    )
    image = M("sensor_msgs/Image")(
        header=header, height=2, width=3, encoding="rgb8", step=9, data=bytes(range(18))
    )
    big = M("std_msgs/Int64")(data=-(2**40))
    flags = M("std_msgs/Bool")(data=True)
    multi = M("std_msgs/Float32MultiArray")(data=[1.5, -2.25, 3.0])
    multi.layout.dim = [M("std_msgs/MultiArrayDimension")(label="n", size=3, stride=3)]
    return [scan, cloud, grid, markers, pose, tf, image, big, flags, multi]


def test_js_decoder_reads_and_writes_what_python_serializes() -> None:
    messages = _messages()
    cases = [
        {"type": m._type, "definition": m._full_text, "hex": m.serialize_to_bytes().hex()} for m in messages
    ]
    proc = subprocess.run(
        [NODE, str(SCRIPT), str(LIB)], input=json.dumps(cases), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0, proc.stderr
    results = json.loads(proc.stdout)
    for msg, case, result in zip(messages, cases, results, strict=True):
        _close(_plain(msg), result["value"], msg._type)
        assert result["hex"] == case["hex"], f"{msg._type}: re-encoded bytes differ"
        assert result["truncatedError"] and "too short" in result["truncatedError"], msg._type


def test_js_decoder_names_the_field_of_a_bad_definition() -> None:
    script = (
        "const {codecFor}=await import(process.argv[1]);"
        "try{codecFor('a/B','int32 x\\nfoo bar baz\\n')}catch(e){console.log(e.message)}"
        "try{codecFor('a/B','a/C c\\n')}catch(e){console.log(e.message)}"
    )
    proc = subprocess.run(
        [NODE, "--input-type=module", "-e", script, LIB.as_uri()], capture_output=True, text=True, timeout=30
    )
    lines = proc.stdout.splitlines()
    assert lines == ["a/B:2: cannot parse 'foo bar baz'", "a/B.c: no definition of a/C in a/B's text"]
