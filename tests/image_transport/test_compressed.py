"""image_transport's compressed transport: format text, parameters, lossless PNG round trips, and
Debian's cv_bridge (python3-opencv) decoding what we encode to the same arrays."""

from __future__ import annotations

import base64
import json
import subprocess

import numpy as np
import pytest

from ninjemys.cv_bridge import CvBridge, CvBridgeError
from ninjemys.image_transport import CompressionParams, decode, encode
from ninjemys.testing import have_ros1

bridge = CvBridge()


def _pattern(h: int = 48, w: int = 64) -> np.ndarray:
    y, x = np.mgrid[0:h, 0:w]
    return np.dstack([(x * 4) % 256, (y * 5) % 256, ((x + y) * 3) % 256]).astype(np.uint8)


def test_format_text_as_compressed_image_transport_writes_it() -> None:
    rgb = bridge.cv2_to_imgmsg(_pattern(), "rgb8")
    assert encode(rgb).format == "rgb8; jpeg compressed bgr8"
    assert encode(rgb, CompressionParams("png")).format == "rgb8; png compressed bgr8"
    mono = bridge.cv2_to_imgmsg(_pattern()[..., 0].copy(), "mono8")
    assert encode(mono).format == "mono8; jpeg compressed mono8"
    assert encode(mono, CompressionParams("png")).format == "mono8; png compressed "
    with pytest.raises(CvBridgeError, match="8 or 16 bit"):
        encode(bridge.cv2_to_imgmsg(np.zeros((2, 2), np.float32), "32FC1"))
    with pytest.raises(CvBridgeError, match="unknown format 'gif'"):
        encode(rgb, CompressionParams("gif"))


@pytest.mark.parametrize(
    "encoding,arr",
    [
        ("rgb8", _pattern()),
        ("bgr8", _pattern()),
        ("mono8", _pattern()[..., 1].copy()),
        ("mono16", (_pattern()[..., 0].astype(np.uint16) * 257)),
        ("16UC1", (_pattern()[..., 2].astype(np.uint16) * 100)),
    ],
)
def test_png_round_trip_is_lossless(encoding: str, arr: np.ndarray) -> None:
    msg = bridge.cv2_to_imgmsg(arr, encoding)
    back = decode(encode(msg, CompressionParams("png", png_level=3)))
    assert back.encoding == encoding
    assert np.array_equal(bridge.imgmsg_to_cv2(back), arr)


def test_jpeg_round_trip_restores_the_encoding_and_quality_matters() -> None:
    arr = _pattern()
    msg = bridge.cv2_to_imgmsg(arr, "rgb8")
    back = decode(encode(msg, CompressionParams("jpeg", jpeg_quality=100)))
    assert back.encoding == "rgb8"
    assert np.abs(bridge.imgmsg_to_cv2(back).astype(int) - arr).mean() < 2.0  # rgb order kept
    small = len(encode(msg, CompressionParams("jpeg", jpeg_quality=10)).data)
    assert small < len(encode(msg, CompressionParams("jpeg", jpeg_quality=95)).data)
    with pytest.raises(CvBridgeError, match="cannot decode"):
        decode(type(encode(msg))(format="jpeg", data=b"not an image"))


_DEBIAN = r"""
import base64, json, sys
import numpy as np, cv2
from cv_bridge import CvBridge
from sensor_msgs.msg import CompressedImage
b = CvBridge()
out = {}
for name, fmt, data in json.loads(sys.stdin.read()):
    m = CompressedImage(format=fmt, data=base64.b64decode(data))
    im = b.compressed_imgmsg_to_cv2(m)
    out[name] = [base64.b64encode(np.ascontiguousarray(im).tobytes()).decode(), list(im.shape), str(im.dtype)]
    rgb = b.compressed_imgmsg_to_cv2(m, "rgb8") if im.ndim == 3 else None
    if rgb is not None:
        out[name + ":rgb8"] = [base64.b64encode(rgb.tobytes()).decode(), list(rgb.shape), str(rgb.dtype)]
    enc = b.cv2_to_compressed_imgmsg(im, "png")
    out[name + ":png"] = [enc.format, base64.b64encode(b.compressed_imgmsg_to_cv2(enc).tobytes()).decode()]
print(json.dumps(out))
"""


@pytest.mark.ros1
@pytest.mark.skipif(not have_ros1(), reason="needs Debian's python3-cv-bridge")
def test_debian_cv_bridge_decodes_ours_to_the_same_arrays() -> None:
    arr = _pattern()
    cases = {
        "rgb_jpeg": encode(bridge.cv2_to_imgmsg(arr, "rgb8")),
        "rgb_png": encode(bridge.cv2_to_imgmsg(arr, "rgb8"), CompressionParams("png")),
        "mono_jpeg": encode(bridge.cv2_to_imgmsg(arr[..., 0].copy(), "mono8")),
        "bridge_jpg": bridge.cv2_to_compressed_imgmsg(arr),
        "bridge_png": bridge.cv2_to_compressed_imgmsg(arr, "png"),
    }
    payload = json.dumps([[k, m.format, base64.b64encode(bytes(m.data)).decode()] for k, m in cases.items()])
    res = subprocess.run(
        ["/usr/bin/python3", "-c", _DEBIAN], input=payload, capture_output=True, text=True, timeout=60
    )
    assert res.returncode == 0, res.stderr
    theirs = json.loads(res.stdout)
    for name, m in cases.items():
        ours = bridge.compressed_imgmsg_to_cv2(m)
        data, shape, dtype = theirs[name]
        assert list(ours.shape) == shape and str(ours.dtype) == dtype, name
        assert base64.b64decode(data) == np.ascontiguousarray(ours).tobytes(), name
        if ours.ndim == 3:
            assert (
                base64.b64decode(theirs[name + ":rgb8"][0])
                == bridge.compressed_imgmsg_to_cv2(m, "rgb8").tobytes()
            )
        fmt, png_pixels = theirs[name + ":png"]
        mine = bridge.cv2_to_compressed_imgmsg(ours, "png")
        assert mine.format == fmt == "png"
        assert base64.b64decode(png_pixels) == bridge.compressed_imgmsg_to_cv2(mine).tobytes()


class _FakePub:
    def __init__(self) -> None:
        self.connections = 0
        self.sent: list = []

    def get_num_connections(self) -> int:
        return self.connections

    def publish(self, msg: object) -> None:
        self.sent.append(msg)


class _FakeNode:
    """Enough of a Node for CompressedPublisher: names, one publisher, parameters, a log."""

    def __init__(self, params: dict) -> None:
        self.pub = _FakePub()
        self.params = params
        self.warnings: list[str] = []
        self.log = type("L", (), {"warn": lambda _s, text: self.warnings.append(text)})()

    def resolve_name(self, name: str) -> str:
        return "/" + name.lstrip("/")

    def publisher(self, topic: str, cls: object, queue_size: int) -> _FakePub:
        return self.pub

    def get_param(self, key: str, default: object) -> object:
        return self.params.get(key, default)


def test_publisher_encodes_only_when_subscribed(monkeypatch: pytest.MonkeyPatch) -> None:
    import ninjemys.image_transport.compressed as mod

    calls: list = []
    real = mod.encode
    monkeypatch.setattr(mod, "encode", lambda m, p: calls.append(p) or real(m, p))
    node = _FakeNode({"/cam/compressed/format": "png", "/cam/compressed/png_level": 1})
    pub = mod.CompressedPublisher(node, "cam")
    assert pub.topic == "/cam/compressed"
    img = bridge.cv2_to_imgmsg(_pattern(), "rgb8")
    pub.publish(img)
    assert calls == [] and node.pub.sent == []  # nobody listens: no CPU spent
    node.pub.connections = 1
    pub.publish(img)
    assert calls == [CompressionParams("png", 80, 1)]
    assert node.pub.sent[0].format == "rgb8; png compressed bgr8"


def test_bad_parameters_warn_and_fall_back() -> None:
    import ninjemys.image_transport.compressed as mod

    node = _FakeNode({"/cam/compressed/format": "gif", "/cam/compressed/jpeg_quality": "high"})
    pub = mod.CompressedPublisher(node, "cam")
    assert pub.params() == CompressionParams()
    assert any("gif" in w for w in node.warnings) and any("jpeg_quality" in w for w in node.warnings)
