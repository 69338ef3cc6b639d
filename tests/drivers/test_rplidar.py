"""rplidar_ros' rplidarNode on an emulated A1: Slamtec's protocol, the known room on /scan within 1 cm in
rplidar_ros' angle convention, a bad descriptor and a health error as clear errors, stop_motor seen by the
device."""

from __future__ import annotations

import math
import os
import re
import subprocess
import time
import xml.etree.ElementTree as ET
import xmlrpc.client
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pytest

from ninjemys import testing
from ninjemys.drivers import rplidar_protocol as rp
from ninjemys.drivers.rplidar_scan import ascend, compensate_multiple, revolution_to_scan
from ninjemys.idl.loader import get_message_class, get_service_class

from .emu_rplidar import EmulatedA1, check_room

if TYPE_CHECKING:
    from .conftest import Rig

LaserScan = get_message_class("sensor_msgs/LaserScan")
Empty = get_service_class("std_srvs/Empty")


# -- the protocol ------------------------------------------------------------------------------------------


def test_requests_descriptors_and_answers_as_the_protocol_document_lays_them_out() -> None:
    assert rp.request(rp.CMD_SCAN) == b"\xa5\x20"
    assert rp.express_scan_request() == bytes.fromhex("a5 82 05 00 00 00 00 00 22")
    assert rp.motor_pwm_request(660) == bytes.fromhex("a5 f0 02 94 02") + bytes(
        (0xA5 ^ 0xF0 ^ 0x02 ^ 0x94 ^ 0x02,)
    )
    d = rp.Descriptor(5, rp.SEND_MODE_MULTIPLE, rp.ANS_TYPE_MEASUREMENT)
    assert d.pack() == bytes.fromhex("a5 5a 05 00 00 40 81")
    assert rp.Descriptor.unpack(d.pack()) == d
    d.check(rp.CMD_SCAN)
    with pytest.raises(
        rp.RplidarError, match=r"answered SCAN \(0x20\) with a response descriptor of length 84"
    ):
        rp.Descriptor(84, 1, 0x82).check(rp.CMD_SCAN)
    info = rp.DeviceInfo(0x18, 0x011D, 7, bytes(16))
    assert len(info.pack()) == 20 and rp.DeviceInfo.unpack(info.pack()) == info


def test_standard_nodes_decode_and_resynchronise_after_noise() -> None:
    stream = rp.pack_node(10.5, 1234.25, 47, True) + b"\x00\x02" + rp.pack_node(11.0, 0, 0, False)
    dec = rp.NodeDecoder()
    rows = [tuple(r) for i in range(len(stream)) for r in dec.feed(stream[i : i + 1])]
    # 10.5 degrees (672/64) reaches rplidar_ros as (672 << 8) // 90 = 1911 q14 = 10.497 degrees
    assert rows[0] == (1911 * 90 / 16384, 1234.25, 47, 1)
    assert rows[-1] == (rp.q14_degrees(704), 0.0, 0, 0)
    assert dec.discarded >= 2


def test_express_capsules_interpolate_angles_between_capsules_with_compensation() -> None:
    dists = [1000.0 + i for i in range(32)]
    caps = rp.pack_capsule(0.0, dists, [0] * 32, start=True) + rp.pack_capsule(30.0, dists, [8] * 32, False)
    caps += rp.pack_capsule(60.0, dists, [0] * 32, False)
    dec = rp.CapsuleDecoder()
    rows = dec.feed(caps)
    # a capsule's samples come out when the next one gives their end angle: the second capsule's are
    # 30 + i * 30/32 degrees, minus 8/8 = 1 degree of compensation
    assert len(rows) == 64
    assert tuple(rows[0][:2]) == (0.0, 1000.0)
    for i, (angle, dist, quality, _) in enumerate(rows[32:]):
        assert angle == rp.q14_degrees(int(round((30.0 + i * 30.0 / 32 - 1.0) * 64)))
        assert dist == 1000.0 + i and quality == 0x2F
    bad = bytearray(rp.pack_capsule(90.0, dists, [0] * 32, False))
    bad[10] ^= 0xFF
    assert len(dec.feed(bytes(bad))) == 0 and dec.bad >= 1


def test_angle_convention_is_pi_minus_the_device_angle_with_reversed_ranges() -> None:
    rev = np.array([[a + 0.5, 1000.0 + a, 10] for a in range(360)], dtype=np.float64)
    f = revolution_to_scan(rev, True, 1, 0.1, False, 12.0)
    assert f.angle_min == pytest.approx(math.pi - math.radians(359))
    assert f.angle_max == pytest.approx(math.pi)
    assert f.angle_increment == pytest.approx(math.radians(1))
    # beam j is at pi - 359 deg + j deg, i.e. device angle 359 - j
    assert f.ranges[0] == pytest.approx(1.359) and f.ranges[-1] == pytest.approx(1.0)
    inv = revolution_to_scan(rev, True, 1, 0.1, True, 12.0)
    assert inv.ranges[0] == pytest.approx(1.0)
    rev[3, 1] = 0.0
    assert np.isinf(revolution_to_scan(rev, True, 1, 0.1, False, 12.0).ranges[359 - 3])
    assert compensate_multiple(500) == 1 and compensate_multiple(125) == 2
    # empty samples get angles from their neighbours and the revolution is sorted
    jumbled = np.array([[200.0, 0, 0], [10.0, 5.0, 1], [5.0, 5.0, 1]])
    assert list(ascend(jumbled)[:, 0]) == sorted(ascend(jumbled)[:, 0])


# -- the node on the emulated device -----------------------------------------------------------------------


@pytest.mark.parametrize("mode", ["Standard", "Express"])
def test_scan_of_the_known_room_within_1cm_and_stop_motor_reaches_the_device(mode: str, rig: Rig) -> None:
    a1 = rig.device(EmulatedA1(samples_per_s=2000.0 if mode == "Standard" else 4000.0))
    node = rig.node("rplidar_test")
    scans = rig.collect(node, "/scan", LaserScan)
    args = [f"_serial_port:={a1.path}", "_frame_id:=laser", "_angle_compensate:=true"]
    proc = rplidar(rig, *args, *([] if mode == "Express" else ["_scan_mode:=Standard"]))
    scans.wait_count(3, timeout=30)
    scan = scans.items[-1]
    assert scan.header.frame_id == "laser"
    assert scan.range_min == pytest.approx(0.15) and scan.range_max == pytest.approx(16.0)
    assert scan.scan_time > 0 and scan.time_increment == pytest.approx(scan.scan_time / 359)
    samples = a1.standard_samples() if mode == "Standard" else a1.express_samples()
    check_room(scan, samples)
    assert rp.CMD_GET_INFO in a1.commands and rp.CMD_GET_HEALTH in a1.commands
    # by rosrun the node has rplidar_ros' ros::init name, rplidar_node (launch files call it rplidarNode)
    _code, _msg, (pubs, _subs, _srvs) = xmlrpc.client.ServerProxy(rig.uri).getSystemState("/t")
    assert dict((t, n) for t, n in pubs)["/scan"] == ["/rplidar_node"]

    before = len(a1.commands)
    node.service_proxy("/stop_motor", Empty)(Empty._request_class())
    a1.wait(lambda: rp.CMD_STOP in a1.commands[before:])
    assert a1.mode is None  # the device stopped streaming
    time.sleep(0.5)
    count = len(scans.items)
    time.sleep(0.5)
    assert len(scans.items) == count  # no scans while stopped
    node.service_proxy("/start_motor", Empty)(Empty._request_class())
    scans.wait_count(count + 2)
    out = rig.stop(proc)
    assert "RPLIDAR S/N: A0A1A2A3A4A5A6A7A8A9AAABACADAEAF" in out, out
    assert "Firmware Ver: 1.29" in out and "Hardware Rev: 7" in out, out
    assert "RPLidar health status : 0" in out, out
    assert f"current scan mode: {mode}, max_distance: 16.0 m" in out, out
    assert "Traceback" not in out, out


def test_a_bad_descriptor_is_one_clear_error_and_the_node_stays_up(rig: Rig) -> None:
    a1 = rig.device(EmulatedA1(bad_scan_descriptor=True))
    proc = rplidar(rig, f"_serial_port:={a1.path}", "_scan_mode:=Standard")
    a1.wait(lambda: a1.commands.count(rp.CMD_SCAN) >= 3)  # retried, once a second
    assert proc.poll() is None
    out = rig.stop(proc)
    line = (
        "Can not start scan: the device answered SCAN (0x20) with a response descriptor of length 84, "
        "send mode 1, type 0x82; expected length 5, send mode 1, type 0x81"
    )
    assert out.count(line) == 1, out
    assert "Traceback" not in out, out


def test_health_error_and_a_missing_port_stop_the_node_as_rplidar_ros_does(rig: Rig, tmp_path: Path) -> None:
    sick = rig.device(EmulatedA1(health=(2, 0x8001)))
    out = rig.exit_output(rplidar(rig, f"_serial_port:={sick.path}"))
    sick.wait(lambda: rp.CMD_RESET in sick.commands, timeout=5)  # the protection stop is reset
    assert rp.CMD_SCAN not in sick.commands and rp.CMD_EXPRESS_SCAN not in sick.commands
    assert "RPLidar health status : 2" in out, out
    assert "Error, rplidar internal error detected. Please reboot the device to retry." in out, out
    out = rig.exit_output(rplidar(rig, f"_serial_port:={tmp_path / 'nothing'}"))
    assert f"Error, cannot bind to the specified serial port {tmp_path / 'nothing'}." in out, out


def test_an_unknown_scan_mode_lists_the_modes_and_waits_for_start_motor_as_rplidar_ros(rig: Rig) -> None:
    """rplidar_ros does not exit here: it prints the modes and ``Can not start scan: 80008001!``, stays
    up without scans, and its ``start_motor`` starts the device's typical mode."""
    a1 = rig.device(EmulatedA1())
    node = rig.node("rplidar_mode_test")
    scans = rig.collect(node, "/scan", LaserScan)
    proc = rplidar(rig, f"_serial_port:={a1.path}", "_scan_mode:=Sensitivity")
    out = rig.read_until(proc, "Can not start scan: 80008001!")
    assert "scan mode `Sensitivity' is not supported by lidar, supported modes:" in out, out
    assert "\tStandard: max_distance: 16.0 m, Point number: 2.0K" in out, out
    time.sleep(1.0)
    assert proc.poll() is None and not scans.items
    assert rp.CMD_SCAN not in a1.commands and rp.CMD_EXPRESS_SCAN not in a1.commands
    node.service_proxy("/start_motor", Empty)(Empty._request_class())
    scans.wait_count(2, timeout=30)
    out += rig.stop(proc)
    assert "current scan mode: Express" in out, out
    assert "Traceback" not in out, out


def test_rplidar_ros_2_parameters_initial_reset_and_channel_type(rig: Rig) -> None:
    """rplidar_ros 2.x's ``initial_reset`` (RESET, wait for the device, go on) works; its Ethernet
    ``channel_type`` is refused in one clear line."""
    a1 = rig.device(EmulatedA1())
    scans = rig.collect(rig.node("rplidar_reset_test"), "/scan", LaserScan)
    proc = rplidar(rig, f"_serial_port:={a1.path}", "_initial_reset:=true")
    scans.wait_count(2, timeout=40)
    out = rig.stop(proc)
    assert rp.CMD_RESET in a1.commands
    assert "Resetting rplidar" in out and "Rplidar reset successfully" in out, out
    out = rig.exit_output(rplidar(rig, "_channel_type:=tcp"))
    assert "Error, channel_type tcp is not supported here" in out, out


def test_rplidar_a1_launch_brings_up_the_node_on_the_emulated_device(rig: Rig) -> None:
    a1 = rig.device(EmulatedA1())
    node = rig.node("rplidar_launch_test")
    scans = rig.collect(node, "/scan", LaserScan)
    rig.roslaunch("rplidar_ros", "rplidar_a1.launch", f"serial_port:={a1.path}")
    scans.wait_count(2, timeout=40)
    scan = scans.items[-1]
    assert scan.header.frame_id == "laser" and len(scan.ranges) == 360  # angle_compensate from the file
    assert node.get_param("/rplidarNode/serial_baudrate") == 115200


def rplidar(rig: Rig, *args: str) -> subprocess.Popen:
    """rplidar_ros' rplidarNode with ``args``."""
    return rig.shipped("rplidar_ros", "rplidarNode", *args)


def test_launch_files_name_the_node_and_its_parameters() -> None:
    from ninjemys.packages.shipped import shipped_executable

    assert shipped_executable("rplidar_ros", "rplidarNode") is not None
    share = Path(__file__).resolve().parents[2] / "src/ninjemys/packages/share/rplidar_ros/launch"
    for name in ("rplidar", "rplidar_a1", "rplidar_a2", "rplidar_a3"):
        text = (share / f"{name}.launch").read_text()
        assert 'type="rplidarNode"' in text and 'name="angle_compensate"' in text
    # rplidar_ros' values, launch file by launch file (1.10's rplidar*.launch, 2.x's per-model files)
    bauds = {"rplidar": 115200, "rplidar_a1": 115200, "rplidar_a2": 115200, "rplidar_a2m8": 115200}
    bauds |= {"rplidar_a2m7": 256000, "rplidar_a2m12": 256000, "rplidar_a3": 256000}
    for name, baud in bauds.items():
        root = ET.parse(share / f"{name}.launch").getroot()
        args = {a.get("name"): a.get("default") for a in root.iter("arg")}
        (node,) = root.iter("node")
        assert (node.get("name"), node.get("pkg"), node.get("type")) == (
            "rplidarNode",
            "rplidar_ros",
            "rplidarNode",
        )
        params = {p.get("name"): p.get("value") for p in node.iter("param")}
        assert args == {"serial_port": "/dev/ttyUSB0", "serial_baudrate": str(baud), "frame_id": "laser"}, (
            name
        )
        assert params["inverted"] == "false" and params["angle_compensate"] == "true", name
        assert params.get("scan_mode") == ("Sensitivity" if name == "rplidar_a3" else None), name


def test_view_launch_files_bring_up_the_lidar_and_rviz_on_its_scan() -> None:
    """rplidar_ros' view_rplidar*.launch: the matching rplidar*.launch and rviz with rplidar.rviz, a
    LaserScan display on /scan in the lidar's frame (read by our rviz's own .rviz reader)."""
    from ninjemys.web.rvizconfig import parse

    share = Path(__file__).resolve().parents[2] / "src/ninjemys/packages/share/rplidar_ros"
    config = parse((share / "rviz/rplidar.rviz").read_text(), "rplidar.rviz")
    assert config.fixed_frame == "laser" and not config.unsupported
    assert [(d["cls"], d["topic"]) for d in config.displays if d["cls"] == "rviz/LaserScan"] == [
        ("rviz/LaserScan", "/scan")
    ]
    for model in ("", "_a1", "_a2", "_a2m7", "_a2m8", "_a2m12", "_a3"):
        root = ET.parse(share / f"launch/view_rplidar{model}.launch").getroot()
        (include,) = root.iter("include")
        assert include.get("file") == f"$(find rplidar_ros)/launch/rplidar{model}.launch"
        (rviz,) = root.iter("node")
        assert (rviz.get("pkg"), rviz.get("type")) == ("rviz", "rviz")
        assert rviz.get("args") == "-d $(find rplidar_ros)/rviz/rplidar.rviz"


def test_view_rplidar_a1_launch_runs_the_lidar_and_rviz(rig: Rig) -> None:
    for var in ("DISPLAY", "WAYLAND_DISPLAY"):
        rig.env.pop(var, None)  # rviz only prints its URL
    a1 = rig.device(EmulatedA1())
    scans = rig.collect(rig.node("rplidar_view_test"), "/scan", LaserScan)
    launch = rig.roslaunch("rplidar_ros", "view_rplidar_a1.launch", f"serial_port:={a1.path}")
    scans.wait_count(2, timeout=40)
    master = xmlrpc.client.ServerProxy(rig.uri)
    deadline = time.monotonic() + 30
    while master.lookupNode("/t", "/rviz")[0] != 1 and time.monotonic() < deadline:
        time.sleep(0.5)  # rviz subscribes once a page shows the scan; its node is up before that
    assert master.lookupNode("/t", "/rviz")[0] == 1
    out = rig.stop(launch)
    assert "process has died" not in out, out[-3000:]


def test_create_and_delete_udev_rules_scripts_write_the_rplidar_symlink_rule(tmp_path: Path) -> None:
    """``rosrun rplidar_ros create_udev_rules.sh`` as tutorials use it (here into a directory of the
    test's: NINJEMYS_UDEV_RULES_DIR), and ``delete_udev_rules.sh`` removing it."""
    env = dict(os.environ, NINJEMYS_UDEV_RULES_DIR=str(tmp_path / "rules.d"))
    rosrun = testing.ninjemys_bin("rosrun")
    made = subprocess.run(
        [rosrun, "rplidar_ros", "create_udev_rules.sh"], env=env, capture_output=True, text=True, timeout=60
    )
    assert made.returncode == 0, made
    rule = (tmp_path / "rules.d/rplidar.rules").read_text()
    (line,) = [x for x in rule.splitlines() if x and not x.startswith("#")]
    fields = re.findall(r'([A-Z]+(?:\{\w+\})?)(==|:=|\+=)"([^"]*)"', line)
    assert fields == [
        ("KERNEL", "==", "ttyUSB*"),
        ("ATTRS{idVendor}", "==", "10c4"),
        ("ATTRS{idProduct}", "==", "ea60"),
        ("MODE", ":=", "0666"),
        ("SYMLINK", "+=", "rplidar"),
    ]
    assert "/dev/rplidar" in made.stdout
    gone = subprocess.run(
        [rosrun, "rplidar_ros", "delete_udev_rules.sh"], env=env, capture_output=True, text=True, timeout=60
    )
    assert gone.returncode == 0, gone
    assert not (tmp_path / "rules.d/rplidar.rules").exists()
