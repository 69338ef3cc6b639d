"""rosserial: the packet codec, and serial_node.py serving an emulated Arduino on a pty (and over TCP).

Debian's real ``rostopic`` reads the board's ``/wl`` and publishes its ``/cmd_vel``; the values round-trip
through the board's kinematics; noise and broken packets are dropped and the link goes on; a board that
stops syncing is asked for its topics again with ROS 1's "Lost sync with device, restarting...".
"""

from __future__ import annotations

import os
import subprocess
import time
import tty
from typing import TYPE_CHECKING

import pytest

from ninjemys import testing
from ninjemys.drivers import rosserial_protocol as proto
from ninjemys.drivers.rosserial_host import RosserialError, param_response_lists
from ninjemys.idl.loader import get_message_class, get_service_class

from .emu_arduino import WHEEL_BASE, EmulatedArduino

if TYPE_CHECKING:
    from .conftest import Rig

Float32 = get_message_class("std_msgs/Float32")
ColorRGBA = get_message_class("std_msgs/ColorRGBA")
Log = get_message_class("rosgraph_msgs/Log")


# -- the codec --------------------------------------------------------------------------------------


def test_frame_layout_and_the_hosts_topic_request() -> None:
    assert proto.REQUEST_TOPICS == b"\xff\xfe\x00\x00\xff\x00\x00\xff"  # what rosserial_python writes
    assert proto.TX_STOP == b"\xff\xfe\x00\x00\xff\x0b\x00\xf4"
    f = proto.frame(125, b"\x01\x02\x03")
    assert f[:5] == b"\xff\xfe\x03\x00\xfc"
    assert f[5:7] == (125).to_bytes(2, "little")
    assert (sum(f[5:]) % 256) == 255
    assert proto.FrameReader().feed(f) == [proto.Frame(125, b"\x01\x02\x03")]


def test_reader_resynchronises_after_noise_and_bad_checksums_byte_by_byte() -> None:
    good = proto.frame(100, b"hello")
    bad_msg = bytearray(proto.frame(101, b"world"))
    bad_msg[-1] ^= 0x55
    bad_len = bytearray(proto.frame(102, b"x"))
    bad_len[4] ^= 0x01
    groovy = b"\xff\xff\x00\x00\xff"  # a Groovy client's version byte, then junk
    stream = b"boot banner\r\n\x00\xfe" + bytes(bad_msg) + bytes(bad_len) + b"\xff\x10" + groovy + good
    reader = proto.FrameReader()
    out = []
    for i in range(len(stream)):  # the worst case: one byte per read
        out += reader.feed(stream[i : i + 1])
    frames = [o for o in out if isinstance(o, proto.Frame)]
    drops = [o for o in out if isinstance(o, proto.Drop)]
    assert frames == [proto.Frame(100, b"hello")]
    assert proto.Drop(proto.DropReason.MSG_CHECKSUM, 101) in drops
    assert proto.Drop(proto.DropReason.LENGTH_CHECKSUM, 0x0101) in drops or any(
        d.reason is proto.DropReason.LENGTH_CHECKSUM for d in drops
    )
    assert proto.Drop(proto.DropReason.VERSION, 0x10) in drops
    assert drops[0].log_line() == "wrong checksum for topic id and msg"
    # rosserial_python's words and levels (noetic SerialClient.py): the version byte as Python 3's repr
    assert proto.Drop(proto.DropReason.VERSION, 0x10).log_lines() == [
        (
            "error",
            "Mismatched protocol version in packet (b'\\x10'): lost sync or rosserial_python is from "
            "different ros release than the rosserial client",
        ),
        ("info", "Protocol version of client is unrecognized, expected Rev 1 (rosserial 0.5+)"),
    ]
    # a Groovy client's 0xFF 0xFF header is refused as Rev 0, as rosserial_python refuses it
    assert proto.Drop(proto.DropReason.VERSION, 0xFF) in drops
    assert proto.Drop(proto.DropReason.VERSION, 0xFF).log_lines()[1] == (
        "info",
        "Protocol version of client is Rev 0 (rosserial 0.4 and earlier), expected Rev 1 (rosserial 0.5+)",
    )
    assert proto.Drop(proto.DropReason.LENGTH_CHECKSUM, 4).log_line() == (
        "Wrong checksum for msg length, length 4, dropping message."
    )
    # and all of it in one read gives the same
    assert [o for o in proto.FrameReader().feed(stream) if isinstance(o, proto.Frame)] == frames


def test_parameter_kinds_as_request_param_carries_them() -> None:
    assert param_response_lists(3) == ([3], [], [])
    assert param_response_lists(True) == ([1], [], [])
    assert param_response_lists([0.5, 1.5]) == ([], [0.5, 1.5], [])
    assert param_response_lists(["a", "b"]) == ([], [], ["a", "b"])
    with pytest.raises(RosserialError, match="dictionary"):
        param_response_lists({"a": 1})
    with pytest.raises(RosserialError, match="same type"):
        param_response_lists([1, "a"])
    assert param_response_lists([True, False]) == ([1, 0], [], [])
    with pytest.raises(RosserialError, match="same type"):
        param_response_lists([1, True])  # rosserial_python compares exact types
    with pytest.raises(RosserialError, match="same type"):
        param_response_lists([1, 2.5])


# -- the node against the emulated board --------------------------------------------------------------


@pytest.fixture
def board():  # noqa: ANN201
    b = EmulatedArduino(rate_hz=20.0)
    yield b
    b.close()


@pytest.mark.ros1
def test_debian_rostopic_reads_wl_and_drives_cmd_vel_through_the_board(
    board: EmulatedArduino, rig: Rig
) -> None:
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    node = rig.node("rosserial_test")
    node.set_param("/wheel_radius", 0.05)
    logs = rig.collect(node, "/rosout", Log)
    wl = rig.collect(node, "/wl", Float32)
    led = node.publisher("/led", ColorRGBA)
    proc = serial_node(rig, f"_port:={board.path}", "_baud:=115200")
    board.wait(lambda: board.configured and board.wheel_radius is not None and board.time_syncs > 0)
    assert board.wheel_radius == pytest.approx(0.05)
    secs, _ = board.host_time
    assert abs(secs - time.time()) < 5  # the host answered the board's time request with its clock
    warn = logs.wait_for(lambda m: m.msg == "PuzzleBot board: motors armed")
    assert warn.level == Log.WARN and warn.name == "/serial_node"

    r = testing.ros1_env(rig.uri)
    echo = subprocess.run(
        ["/usr/bin/rostopic", "echo", "-n", "1", "/wl"],
        env=r,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert "data: 0.0" in echo.stdout, echo
    info = subprocess.run(
        ["/usr/bin/rostopic", "info", "/cmd_vel"], env=r, capture_output=True, text=True, timeout=30
    )
    assert "Type: geometry_msgs/Twist" in info.stdout and "/serial_node" in info.stdout, info
    pub = subprocess.run(
        [
            "/usr/bin/rostopic",
            "pub",
            "-1",
            "/cmd_vel",
            "geometry_msgs/Twist",
            "{linear: {x: 0.2}, angular: {z: 1.0}}",
        ],
        env=r,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert pub.returncode == 0, pub
    board.wait(lambda: any(t.linear.x == pytest.approx(0.2) for t in board.cmd_vels))
    expected_wl = (0.2 - 1.0 * WHEEL_BASE / 2) / 0.05
    got = wl.wait_for(lambda m: abs(m.data - expected_wl) < 1e-4)
    assert got.data == pytest.approx(expected_wl, abs=1e-5)
    echo = subprocess.run(
        ["/usr/bin/rostopic", "echo", "-n", "1", "/wr"],
        env=r,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert "data: 5.9" in echo.stdout, echo  # (0.2 + 0.095) / 0.05 = 5.9 in float32

    led.publish(ColorRGBA(r=1.0, g=0.5, b=0.0, a=1.0))
    board.wait(lambda: any(c.g == 0.5 for c in board.leds))

    call = subprocess.run(
        ["/usr/bin/rosservice", "call", "/reset_encoders"],
        env=r,
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert "success: True" in call.stdout and "encoders reset (1)" in call.stdout, call

    # noise, a broken packet and a bad length, then the link goes on without a restart
    count = len(wl.items)
    bad = bytearray(proto.frame(125, Float32(data=99.0).serialize_to_bytes()))
    bad[-1] ^= 0xFF
    board.inject(b"\x00garbage\xff\x13" + bytes(bad) + b"\xff\xfe\x04\x00\x00" + b"\x00" * 8)
    wl.wait_for(lambda m: len(wl.items) > count + 10)
    assert not [m for m in wl.items if m.data == 99.0]
    assert board.negotiations == 1  # recovered without asking for the topics again
    out = rig.stop(proc)
    assert board.stopped_by_host  # rosserial_python's TX_STOP at shutdown
    assert "wrong checksum for topic id and msg" in out, out
    assert "Mismatched protocol version in packet (b'\\x13')" in out, out
    assert "Wrong checksum for msg length, length 4, dropping message." in out, out
    assert "Setup publisher on wl [std_msgs/Float32]" in out, out
    assert "Setup subscriber on cmd_vel [geometry_msgs/Twist]" in out, out
    assert f"Connecting to {board.path} at 115200 baud" in out, out
    assert "Traceback" not in out, out


def test_lost_sync_is_logged_and_the_topics_are_requested_again(board: EmulatedArduino, rig: Rig) -> None:
    node = rig.node("rosserial_sync_test")
    node.set_param("/wheel_radius", 0.05)
    diagnostics = rig.collect(node, "/diagnostics", get_message_class("diagnostic_msgs/DiagnosticArray"))
    proc = serial_node(rig, board.path, "_sync_timeout:=1.0", "__name:=arduino")
    board.wait(lambda: board.configured)
    board.sync_enabled = False  # a sketch stuck without spinOnce's time sync
    board.wait(lambda: board.negotiations >= 2, timeout=15)
    board.sync_enabled = True
    # rosserial_python's ERROR status on /diagnostics for it
    diag = diagnostics.wait_for(lambda m: m.status and m.status[0].message == "no sync with device")
    status = diag.status[0]
    assert (status.name, status.level) == ("rosserial_python", 2)
    assert [kv.key for kv in status.values] == ["last sync", "last sync lost"]
    out = rig.stop(proc)
    assert "Sending tx stop request" in out, out
    assert "Lost sync with device, restarting..." in out, out
    # once a good packet came, it stays "lost sync" (rosserial_python never resets its `synced`)
    assert "Unable to sync" not in out, out
    assert out.count("Requesting topics...") >= 2, out


class _SilentBoard:
    """A pty nobody answers on: a board with the wrong sketch, or a wrong baud rate's garbage."""

    def __init__(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.path = os.ttyname(self.slave)

    def close(self) -> None:
        os.close(self.master)
        os.close(self.slave)


def test_a_board_that_never_answers_is_unable_to_sync_and_asked_again(rig: Rig) -> None:
    b = rig.device(_SilentBoard())
    os.write(b.master, b"\x00\x13 wrong baud rate \xfe\x01")  # noise, no packet
    proc = serial_node(rig, b.path, "_sync_timeout:=1.0")
    rig.read_until(
        proc,
        "Unable to sync with device; possible link problem or link software version "
        "mismatch such as hydro rosserial_python with groovy Arduino",
    )
    out = rig.stop(proc)
    assert "Lost sync with device" not in out, out  # it never had a good packet
    assert "Traceback" not in out, out


def test_a_device_with_an_unknown_md5_gets_one_clear_error_and_the_rest_works(rig: Rig) -> None:
    """Under rosserial_server's serial_node: the board's log levels on /rosout, RequestParam's int,
    float and string arrays, and two endpoints the host cannot serve, each one clear error."""
    from .emu_arduino import _info

    b = rig.device(EmulatedArduino())
    logs = rig.collect(rig.node("rosserial_levels_test"), "/rosout", Log)
    proc = serial_node(rig, f"_port:={b.path}", package="rosserial_server", exe="serial_node")
    b.wait(lambda: b.configured)
    # every level of the board's nh.logxxx() reaches /rosout at rosgraph_msgs/Log's level
    DeviceLog = get_message_class("rosserial_msgs/Log")
    for level in (DeviceLog.INFO, DeviceLog.WARN, DeviceLog.ERROR, DeviceLog.FATAL, 7):
        b.send(proto.ID_LOG, DeviceLog(level=level, msg=f"board level {level}").serialize_to_bytes())
    for level, expected in ((1, Log.INFO), (2, Log.WARN), (3, Log.ERROR), (4, Log.FATAL)):
        got = logs.wait_for(lambda m, n=level: m.msg == f"board level {n}")
        assert got.level == expected and got.name == "/rosserial_server_serial_node"
    # nh.getParam() of int, float and string arrays, a relative and a private name, end to end
    node = rig.node("rosserial_param_test")
    node.set_param("/gains", [3, 4, 5])
    node.set_param("/offsets", [0.5, -1.25])
    node.set_param("/rosserial_server_serial_node/names", ["left", "right"])
    b.param_answers_only = True
    RequestParam = get_service_class("rosserial_msgs/RequestParam")
    for name in ("gains", "offsets", "~names", "/no_such_param"):
        b.send(proto.ID_PARAMETER_REQUEST, RequestParam._request_class(name=name).serialize_to_bytes())
    b.wait(lambda: len(b.param_answers) >= 3)  # no answer to a missing one (nor to wheel_radius here)
    answers = [(list(a.ints), list(a.floats), list(a.strings)) for a in b.param_answers]
    assert answers == [([3, 4, 5], [], []), ([], [0.5, -1.25], []), ([], [], ["left", "right"])]
    # a message larger than the board's input buffer (280 bytes, announced with its subscribers) is
    # dropped with rosserial_python's error instead of overrunning the board; smaller ones go through
    String = get_message_class("std_msgs/String")
    b.send(proto.ID_SUBSCRIBER, _info(110, "display", "std_msgs/String", String._md5sum))
    display = rig.node("rosserial_buffer_test").publisher("/display", String)
    deadline = time.monotonic() + 20
    while not any(t == 110 for t, _ in b.received) and time.monotonic() < deadline:
        display.publish(String(data="x" * 300))
        display.publish(String(data="hello"))
        time.sleep(0.2)
    assert (110, 9) in b.received and not [n for t, n in b.received if t == 110 and n > 280]
    b.send(proto.ID_PUBLISHER, _info(130, "odd", "std_msgs/Float32", "0" * 32))
    b.send(proto.ID_PUBLISHER, _info(131, "nope", "no_such_pkg/Thing", "0" * 32))
    time.sleep(1.0)
    assert proc.poll() is None
    # rosserial_server's serial_node runs under its own default name, as ros::init names it
    assert _publishers(rig, "/wl") == ["/rosserial_server_serial_node"]
    out = rig.stop(proc)
    assert "Creation of publisher failed: Checksum does not match: " in out, out
    assert "Creation of publisher failed:" in out and "no_such_pkg" in out, out
    assert "board level 7" not in out  # a level rosserial_python does not know is dropped, as there
    assert "Message from ROS network dropped: message larger than buffer." in out, out
    assert "Parameter /no_such_param does not exist" in out, out
    assert "Traceback" not in out, out


def test_tcp_mode_serves_a_wifi_board_whose_sketch_calls_a_ros_service(
    board: EmulatedArduino, rig: Rig
) -> None:
    port = testing.free_port()
    node = rig.node("rosserial_tcp_test")
    node.set_param("/wheel_radius", 0.1)
    wr = rig.collect(node, "/wr", Float32)
    Trigger = get_service_class("std_srvs/Trigger")
    node.service(
        "/board_config",
        Trigger,
        lambda _req: Trigger._response_class(success=True, message="gains 1.5 0.2"),
    )
    proc = serial_node(rig, "tcp", str(port))
    board.connect_tcp(port)
    board.wait(lambda: board.configured and board.wheel_radius is not None)
    assert board.wheel_radius == pytest.approx(0.1)
    wr.wait_for(lambda m: m.data == 0.0)
    board.call_config()
    board.wait(lambda: bool(board.config_answers))
    assert board.config_answers[0].success and board.config_answers[0].message == "gains 1.5 0.2"
    out = rig.stop(proc)
    assert f"Waiting for socket connections on port {port}" in out, out
    assert "Established a socket connection from 127.0.0.1" in out, out
    assert out.count("Waiting for socket connection\n") == 1 and "calling startSerialClient" in out, out


def test_rosserial_server_serial_launch_and_rosserial_arduinos_serial_node(rig: Rig) -> None:
    """The names users' launch files use: ``roslaunch rosserial_server serial.launch port:=...`` (node
    ``rosserial_server``), ``rosrun rosserial_arduino serial_node.py PORT`` (node ``serial_node``) and
    ``message_info_service.py``, which rosserial keeps only to say it is no longer needed."""
    rig.node("rosserial_names_test").set_param("/wheel_radius", 0.05)
    b = rig.device(EmulatedArduino())
    launch = rig.roslaunch("rosserial_server", "serial.launch", f"port:={b.path}")
    b.wait(lambda: b.configured and b.wheel_radius is not None)
    assert _publishers(rig, "/wl") == ["/rosserial_server"]
    rig.stop(launch)
    b.wait(lambda: not b.configured)  # the host's TX_STOP as it went down

    b2 = rig.device(EmulatedArduino())
    arduino = rig.shipped("rosserial_arduino", "serial_node.py", b2.path)
    info = rig.shipped("rosserial_python", "message_info_service.py")
    b2.wait(lambda: b2.configured and b2.wheel_radius is not None)
    assert _publishers(rig, "/wr") == ["/serial_node"]
    rig.read_until(info, "no longer needed")
    assert info.poll() is None  # it stays up, as ROS 1's spins
    out = rig.stop(arduino)
    assert "Setup publisher on wr [std_msgs/Float32]" in out, out


def test_tcp_port_falls_back_to_rosserial_embeddedlinux(board: EmulatedArduino, rig: Rig) -> None:
    port = testing.free_port()
    node = rig.node("rosserial_tcp_param_test")
    node.set_param("/rosserial_embeddedlinux/tcp_port", port)
    node.set_param("/wheel_radius", 0.05)
    proc = serial_node(rig, "_port:=tcp")  # "tcp" as the port parameter works as the argument does
    rig.read_until(proc, f"Waiting for socket connections on port {port}")
    board.connect_tcp(port)
    board.wait(lambda: board.configured)


def _publishers(rig: Rig, topic: str) -> list[str]:
    import xmlrpc.client

    _code, _msg, (pubs, _subs, _srvs) = xmlrpc.client.ServerProxy(rig.uri).getSystemState("/test")
    return next((nodes for name, nodes in pubs if name == topic), [])


def serial_node(
    rig: Rig, *args: str, package: str = "rosserial_python", exe: str = "serial_node.py"
) -> subprocess.Popen:
    return rig.shipped(package, exe, *args)
