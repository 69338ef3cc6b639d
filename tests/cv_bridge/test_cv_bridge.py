"""cv_bridge with numpy only: raw conversions (against Debian's python3-cv-bridge), compressed via Pillow."""

from __future__ import annotations

import base64
import io
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from cv_bridge import CvBridge, CvBridgeError
from ninjemys.cv_bridge.encodings import dtype_and_channels
from ninjemys.idl.loader import get_message_class
from ninjemys.testing import ROS1_PYTHON, ros1_env

Image = get_message_class("sensor_msgs/Image")
ORACLE = Path(__file__).with_name("cvb_oracle.py")
SOURCES = ["rgb8", "bgr8", "rgba8", "bgra8", "mono8", "mono16", "rgb16", "bgr16", "rgba16", "bgra16",
           "8UC3", "8UC1", "16UC1", "32FC1", "64FC1", "8SC1", "16SC3", "yuv422", "bayer_rggb8"]  # fmt: skip
TARGETS = ["passthrough", "rgb8", "bgr8", "rgba8", "bgra8", "mono8", "mono16", "rgb16", "bgr16", "bgra16",
           "8UC3", "8UC1", "16UC1", "32FC1", "8UC4", "yuv422", "bogus"]  # fmt: skip


def image(encoding: str, seed: int, width: int = 6, height: int = 4) -> object:
    rng = np.random.default_rng(seed)
    dtype, channels = dtype_and_channels(encoding)
    shape = (height, width, channels)
    if np.dtype(dtype).kind == "f":
        arr = rng.uniform(-2, 300, shape).astype(dtype)
    else:
        info = np.iinfo(dtype)
        arr = rng.integers(info.min, info.max, shape, endpoint=True).astype(dtype)
    msg = Image(
        height=height, width=width, encoding=encoding, is_bigendian=0, step=width * channels * arr.itemsize
    )
    msg.data = arr.tobytes()
    return Image.deserialize_from(msg.serialize_to_bytes())


def test_roundtrip_and_step_padding() -> None:
    bridge = CvBridge()
    arr = np.arange(4 * 5 * 3, dtype=np.uint16).reshape(4, 5, 3)
    msg = bridge.cv2_to_imgmsg(arr, "rgb16")
    assert (msg.encoding, msg.step, msg.height, msg.width) == ("rgb16", 30, 4, 5)
    back = bridge.imgmsg_to_cv2(msg)
    assert np.array_equal(back, arr) and not back.flags.writeable
    assert bridge.cv2_to_imgmsg(arr).encoding == "16UC3"
    padded = Image(height=2, width=3, encoding="mono8", step=4, data=bytes([1, 2, 3, 0, 4, 5, 6, 0]))
    assert bridge.imgmsg_to_cv2(padded).tolist() == [[1, 2, 3], [4, 5, 6]]
    with pytest.raises(CvBridgeError, match="needs step >= 3 and 8 bytes of data, got step 4 and 5 bytes"):
        bridge.imgmsg_to_cv2(Image(height=2, width=3, encoding="mono8", step=4, data=bytes(5)))
    with pytest.raises(CvBridgeError, match="incompatible type 16UC3"):
        bridge.cv2_to_imgmsg(arr, "bgr8")
    with pytest.raises(TypeError):
        bridge.cv2_to_imgmsg([[1]])
    big = bridge.cv2_to_imgmsg(arr.astype(">u2"), "rgb16")
    assert big.is_bigendian and np.array_equal(bridge.imgmsg_to_cv2(big), arr)


def test_color_conversions() -> None:
    bridge = CvBridge()
    rgb = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 20, 30]]], dtype=np.uint8)
    msg = bridge.cv2_to_imgmsg(rgb, "rgb8")
    assert bridge.imgmsg_to_cv2(msg, "bgr8")[0, 0].tolist() == [0, 0, 255]
    assert bridge.imgmsg_to_cv2(msg, "rgba8")[0, 3].tolist() == [10, 20, 30, 255]
    assert bridge.imgmsg_to_cv2(msg, "mono8")[0].tolist() == [76, 150, 29, 18]
    assert bridge.imgmsg_to_cv2(msg, "mono16")[0, 0] == 76 * 257
    with pytest.raises(CvBridgeError, match=r"Unsupported conversion from \[rgb8\] to \[yuv422\]"):
        bridge.imgmsg_to_cv2(msg, "yuv422")
    with pytest.raises(CvBridgeError, match=r"Unrecognized image encoding \[bogus\]"):
        bridge.imgmsg_to_cv2(msg, "bogus")
    assert bridge.imgmsg_to_cv2(image("bayer_rggb8", 1), "bgr8").shape[-1] == 3  # OpenCV demosaics


def _hide_cv2(monkeypatch: pytest.MonkeyPatch) -> None:
    """A Python without OpenCV: the numpy and Pillow paths (cv2 is a dependency, but optional here)."""
    import builtins

    real_import = builtins.__import__

    def no_cv2(name, *args, **kwargs):  # type: ignore[no-untyped-def]
        if name == "cv2":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_cv2)


def test_without_opencv_numpy_conversions_and_bayer_error(monkeypatch: pytest.MonkeyPatch) -> None:
    _hide_cv2(monkeypatch)
    bridge = CvBridge()
    rgb = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 20, 30]]], dtype=np.uint8)
    msg = bridge.cv2_to_imgmsg(rgb, "rgb8")
    assert bridge.imgmsg_to_cv2(msg, "mono8")[0].tolist() == [76, 150, 29, 18]
    assert bridge.imgmsg_to_cv2(msg, "bgra8")[0, 3].tolist() == [30, 20, 10, 255]
    with pytest.raises(CvBridgeError, match="needs OpenCV"):
        bridge.imgmsg_to_cv2(image("bayer_rggb8", 1), "bgr8")


def test_compressed_bad_format_is_one_clear_error() -> None:
    with pytest.raises(CvBridgeError, match="cannot encode .* as xyz"):
        CvBridge().cv2_to_compressed_imgmsg(np.zeros((2, 2, 3), np.uint8), "xyz")


def test_compressed_with_pillow(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("PIL")
    _hide_cv2(monkeypatch)
    bridge = CvBridge()
    bgr = np.zeros((8, 8, 3), dtype=np.uint8)
    bgr[..., 0] = 200  # blue in OpenCV order
    png = bridge.cv2_to_compressed_imgmsg(bgr, dst_format="png")
    assert png.format == "png" and bytes(png.data[:4]) == b"\x89PNG"
    assert np.array_equal(bridge.compressed_imgmsg_to_cv2(png), bgr)
    assert bridge.compressed_imgmsg_to_cv2(png, "rgb8")[0, 0].tolist() == [0, 0, 200]
    jpg = bridge.cv2_to_compressed_imgmsg(bgr)
    assert jpg.format == "jpg" and bytes(jpg.data[:2]) == b"\xff\xd8"
    assert np.abs(bridge.compressed_imgmsg_to_cv2(jpg).astype(int) - bgr).max() <= 3
    gray = bridge.compressed_imgmsg_to_cv2(
        bridge.cv2_to_compressed_imgmsg(bgr[..., 0].copy(), "png"), "mono8"
    )
    assert gray.shape == (8, 8) and gray[0, 0] == 200
    with pytest.raises(CvBridgeError, match="Pillow cannot write format 'xyz'"):
        bridge.cv2_to_compressed_imgmsg(bgr, "xyz")


def test_compressed_without_codecs_names_both(monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    real_import = builtins.__import__

    def no_codecs(name, *args, **kwargs):
        if name in ("cv2", "PIL"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_codecs)
    with pytest.raises(CvBridgeError, match=r"OpenCV \(pip install opencv-python-headless\) or Pillow"):
        CvBridge().cv2_to_compressed_imgmsg(np.zeros((2, 2), np.uint8))


@pytest.mark.ros1
def test_raw_conversions_match_ros1() -> None:
    images = [image(enc, seed) for seed, enc in enumerate(SOURCES)]
    arrays = [
        (np.zeros((3, 4, 3), np.uint8), "bgr8"),
        (np.arange(12, dtype=np.uint16).reshape(3, 4), "mono16"),
        (np.arange(12, dtype=np.float32).reshape(3, 4), "passthrough"),
        (np.ones((3, 4, 4), np.uint8), "rgba8"),
        (np.ones((3, 4, 3), np.uint8), "mono8"),
        (np.arange(24, dtype=np.int16).reshape(2, 4, 3), "passthrough"),
    ]
    spec = {
        "images": [base64.b64encode(m.serialize_to_bytes()).decode() for m in images],
        "targets": TARGETS,
        "arrays": [],
    }
    for arr, enc in arrays:
        buf = io.BytesIO()
        np.save(buf, arr)
        spec["arrays"].append([base64.b64encode(buf.getvalue()).decode(), enc])
    done = subprocess.run(
        [ROS1_PYTHON, str(ORACLE)], input=json.dumps(spec), capture_output=True, text=True,
        env=ros1_env("http://localhost:1/"), timeout=120,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    theirs = json.loads(done.stdout)
    bridge = CvBridge()
    mismatches = []
    for src, msg, row in zip(SOURCES, images, theirs["convert"], strict=True):
        for target, expected in zip(TARGETS, row, strict=True):
            if src.startswith("bayer") and target != "passthrough" and expected != "ERR":
                continue  # demosaicing needs OpenCV, which this venv does not have
            try:
                ours = np.ascontiguousarray(bridge.imgmsg_to_cv2(msg, target))
                got = [list(ours.shape), ours.dtype.str, base64.b64encode(ours.tobytes()).decode()]
            except CvBridgeError:
                got = "ERR"
            if got != expected:
                mismatches.append(
                    f"{src} -> {target}: ours {'ERR' if got == 'ERR' else got[:2]}, ROS 1 {'ERR' if expected == 'ERR' else expected[:2]}"
                )
    assert mismatches == []
    for (arr, enc), expected in zip(arrays, theirs["to_msg"], strict=True):
        try:
            got = base64.b64encode(bridge.cv2_to_imgmsg(arr, enc).serialize_to_bytes()).decode()
        except CvBridgeError:
            got = "ERR"
        assert got == expected, enc


OPENCV_PROGRAM = """
import numpy as np, cv2
from cv_bridge import CvBridge
import ninjemys.cv_bridge
assert ninjemys.cv_bridge.__file__.startswith(SRC), ninjemys.cv_bridge.__file__
bridge = CvBridge()
bgr = (np.arange(16 * 16 * 3) % 251).astype(np.uint8).reshape(16, 16, 3)
for fmt in ("jpg", "png"):
    msg = bridge.cv2_to_compressed_imgmsg(bgr, fmt)
    assert bytes(msg.data) == cv2.imencode("." + fmt, bgr)[1].tobytes(), fmt
    assert np.array_equal(bridge.compressed_imgmsg_to_cv2(msg), cv2.imdecode(np.frombuffer(bytes(msg.data), np.uint8), -1))
mosaic = (np.arange(8 * 8) % 256).astype(np.uint8).reshape(8, 8)
raw = bridge.cv2_to_imgmsg(mosaic, "bayer_rggb8")
assert np.array_equal(bridge.imgmsg_to_cv2(raw, "bgr8"), cv2.cvtColor(mosaic, cv2.COLOR_BayerBG2BGR))
print("ok")
"""


@pytest.mark.ros1
def test_opencv_path_when_installed() -> None:
    """Under Debian's python (which has cv2), our cv_bridge uses OpenCV for compression and Bayer."""
    src = str(Path(__file__).parents[2] / "src")
    env = ros1_env("http://localhost:1/", PYTHONPATH=src)
    program = f"SRC = {src!r}\n" + OPENCV_PROGRAM
    done = subprocess.run([ROS1_PYTHON, "-c", program], capture_output=True, text=True, env=env, timeout=60)
    assert done.stdout.strip() == "ok", done.stderr
