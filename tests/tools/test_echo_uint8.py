"""A received ``uint8[]`` (a zero-copy memoryview in ours, ``bytes`` in genpy) as rostopic echo and
``str(msg)`` print it, beside Debian's genpy on the same wire bytes."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.tools.echo_format import EchoPrinter

UInt8MultiArray = get_message_class("std_msgs/UInt8MultiArray")
CompressedImage = get_message_class("sensor_msgs/CompressedImage")


def _received(cls: type, **fields: object) -> object:
    return cls.deserialize_from(cls(**fields).serialize_to_bytes())


def test_a_uint8_field_echoed_alone_prints_numbers() -> None:
    msg = _received(UInt8MultiArray, data=bytes([1, 2, 255, 65]))
    assert isinstance(msg.data, memoryview)  # still the zero-copy view
    assert EchoPrinter().render(msg.data) == "[1, 2, 255, 65]\n---\n"  # was b'\x01\x02\xffA'
    assert EchoPrinter().render(msg).endswith("data: [1, 2, 255, 65]\n---\n")


@pytest.mark.skipif(shutil.which("python3", path="/usr/bin") is None, reason="no Debian python3")
def test_str_of_a_received_message_reads_as_debians_genpy() -> None:
    msg = _received(CompressedImage, format="jpeg", data=bytes([0xFF, 0xD8, 0x41]))
    wire = msg.serialize_to_bytes()
    script = (
        "import sys\n"
        "try:\n    from sensor_msgs.msg import CompressedImage\nexcept ImportError:\n    sys.exit(3)\n"
        "m = CompressedImage().deserialize(bytes.fromhex(sys.argv[1]))\n"
        "sys.stdout.write(str(m))\n"
    )
    out = subprocess.run(
        ["/usr/bin/python3", "-c", script, wire.hex()], capture_output=True, text=True, timeout=60
    )
    if out.returncode == 3:
        pytest.skip("Debian's sensor_msgs is not installed")
    assert out.returncode == 0, out.stderr
    assert str(msg) == out.stdout  # data: [255, 216, 65]
