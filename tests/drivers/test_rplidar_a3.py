"""RPLIDAR A3/S scan modes: GET_LIDAR_CONF's mode list, the ultra and dense capsule formats, and
``roslaunch rplidar_ros rplidar_a3.launch`` (scan_mode Sensitivity) on an emulated A3 with /scan matching
the room within 1 cm; corrupted capsules are dropped with a warning and the scans go on."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pytest

from ninjemys.drivers import rplidar_capsules as rc
from ninjemys.drivers import rplidar_protocol as rp
from ninjemys.drivers.rplidar_scan import compensate_multiple
from ninjemys.idl.loader import get_message_class

from .emu_rplidar import A3_MODES, EmulatedA3, ModeInfo, check_room
from .test_rplidar import rplidar

if TYPE_CHECKING:
    from .conftest import Rig

LaserScan = get_message_class("sensor_msgs/LaserScan")
ULTRA = rp.ANS_TYPE_MEASUREMENT_CAPSULED_ULTRA
DENSE = rp.ANS_TYPE_MEASUREMENT_DENSE_CAPSULED


# -- the formats -------------------------------------------------------------------------------------------


def test_get_lidar_conf_request_and_answer() -> None:
    req = rp.lidar_conf_request(rp.CONF_SCAN_MODE_NAME, 3)
    assert req[:3] == bytes((0xA5, 0x84, 36))
    assert req[3:9] == bytes.fromhex("7f000000 0300") and req[9:39] == bytes(30)
    cs = 0
    for b in req[:-1]:
        cs ^= b
    assert req[-1] == cs
    assert rp.parse_lidar_conf(0x7F, b"\x7f\x00\x00\x00Sensitivity\x00") == b"Sensitivity\x00"
    with pytest.raises(rp.RplidarError, match="asked for entry 0x70 and was answered 0x71"):
        rp.parse_lidar_conf(0x70, b"\x71\x00\x00\x00\x05\x00")
    with pytest.raises(rp.RplidarError, match="without a value"):
        rp.parse_lidar_conf(0x70, b"\x70\x00\x00\x00")
    with pytest.raises(rp.RplidarError, match=r"expected send mode 0, type 0x20"):
        rp.Descriptor(8, 1, 0x20).check_single(rp.CMD_GET_LIDAR_CONF, rp.ANS_TYPE_GET_LIDAR_CONF)


def test_variable_bit_scale_of_ultra_majors() -> None:
    # 1 mm steps below 512 mm, then 2, 4, 8 and 16 mm steps (Slamtec's scale table)
    scaled = np.array([0, 511, 512, 1279, 1280, 1792, 3328, 4095])
    value, shift = rc.varbitscale_decode(scaled)
    assert value.tolist() == [0, 511, 512, 2046, 2048, 4096, 16384, 16384 + 767 * 16]
    assert shift.tolist() == [0, 0, 1, 1, 2, 3, 4, 4]
    for mm in (0, 300, 1001, 2500, 5003, 20000):
        decoded = rc.varbitscale_decode(np.array([rc.varbitscale_encode(mm)]))[0][0]
        assert abs(decoded - mm) <= 8


def test_ultra_capsule_decodes_majors_predictions_and_angle_compensation() -> None:
    # cabin 0: major 1000 mm (scaled 756: 512 + 2 * 244), predictions +3 and -2 (2 mm steps): 1006 mm
    # and the next cabin's major (1100 mm) - 4 mm; cabin 1 has "no echo" (0x1FF) predictions
    majors = [756, 512 + 294] + [756] * 30
    words = [majors[0] | 3 << 12 | (-2 & 0x3FF) << 22, majors[1] | 0x1FF << 12 | 0x1FF << 22]
    words += [m | 0 << 12 | 0 << 22 for m in majors[2:]]
    cabins = rp.struct.pack("<32I", *words)
    first = rc.pack_ultra_capsule(0.0, cabins, start=True)
    second = rc.pack_ultra_capsule(90.0, cabins, start=False)
    third = rc.pack_ultra_capsule(180.0, cabins, start=False)
    dec = rp.CapsuleDecoder(rp.ULTRA_CAPSULE_SIZE, rc.ultra_samples)
    rows = dec.feed(first + second + third)
    assert len(rows) == 2 * 96 and dec.bad == 0
    rows = rows[96:]  # the second capsule's (from 90 degrees), closed by the third
    assert rows[:6, 1].tolist() == [1000.0, 1006.0, 1096.0, 1100.0, 0.0, 0.0]
    # 90 degrees over 96 samples; a 1000 mm echo is compensated by
    # (8 deg in rad q16 = 9150) - (98361 // 4000 = 24) << 6 = 7614 -> 7614 * 180 / pi = 436250 (q16 deg)
    assert rc.ultra_offset_deg(1000) == pytest.approx(436250 / 65536)
    assert rows[0, 0] == rp.q14_degrees((((90 * 64) << 10) - 436250) >> 10)
    # no echo: 7.5 degrees (8578 rad q16)
    raw_q16 = ((90 * 64) << 10) + 4 * (90 << 16) // 96
    assert rows[4, 0] == rp.q14_degrees((raw_q16 - int(8578 * 180 / 3.14159265)) >> 10)
    assert rows[4, 2] == 0 and rows[0, 2] == 0x2F


def test_dense_capsule_spreads_40_samples_without_compensation() -> None:
    caps = [rc.pack_dense_capsule(a, [500 + i for i in range(40)], start=(a == 0)) for a in (0.0, 15.0, 30.0)]
    dec = rp.CapsuleDecoder(rp.CAPSULE_SIZE, rc.dense_samples)
    rows = dec.feed(b"".join(caps))
    assert len(rows) == 80
    rows = rows[40:]
    assert rows[:, 0].tolist() == [rp.q14_degrees(int((15.0 + i * 15.0 / 40) * 64)) for i in range(40)]
    assert rows[:, 1].tolist() == [500.0 + i for i in range(40)]


def test_bad_capsules_are_dropped_and_the_stream_resynchronises() -> None:
    cabins, _ = rc.pack_ultra_cabins([1500] * 96, rc.varbitscale_encode(1500))
    caps = [rc.pack_ultra_capsule(a * 22.5, cabins, start=(a == 0)) for a in range(6)]
    broken = bytearray(caps[2])
    broken[50] ^= 0xFF
    dec = rp.CapsuleDecoder(rp.ULTRA_CAPSULE_SIZE, rc.ultra_samples)
    rows = dec.feed(caps[0] + caps[1] + bytes(broken) + b"\x13\x37" + caps[3] + caps[4] + caps[5])
    # 0 -> 1 decodes; capsule 1 loses its end angle with capsule 2; 3 -> 4 and 4 -> 5 decode
    assert dec.bad > 0 and len(rows) == 3 * 96
    assert rows[96, 0] == pytest.approx(3 * 22.5 - rc.ultra_offset_deg(1500), abs=1 / 64 + 90 / 16384)


# -- the node on an emulated A3 ----------------------------------------------------------------------------


def test_rplidar_a3_launch_streams_sensitivity_and_the_room_matches_within_1cm(rig: Rig) -> None:
    a3 = rig.device(EmulatedA3(corrupt_every=40))
    node = rig.node("rplidar_a3_test")
    scans = rig.collect(node, "/scan", LaserScan)
    launch = rig.roslaunch("rplidar_ros", "rplidar_a3.launch", f"serial_port:={a3.path}")
    scans.wait_count(4, timeout=40)
    assert node.get_param("/rplidarNode/serial_baudrate") == 256000
    assert node.get_param("/rplidarNode/scan_mode") == "Sensitivity"
    assert a3.mode == ULTRA and a3.working_mode == 3
    scan = scans.items[-1]
    assert scan.header.frame_id == "laser" and scan.range_max == pytest.approx(25.0)
    multiple = compensate_multiple(16000 >> 8)
    assert multiple == 4
    check_room(scan, a3.mode_samples(ULTRA), multiple)
    assert a3.corrupted > 0
    count = len(scans.items)
    scans.wait_count(count + 3)  # corrupted capsules do not stop the stream
    out = rig.stop(launch)
    assert "current scan mode: Sensitivity, max_distance: 25.0 m, Point number: 16.1K" in out, out
    assert "RPLIDAR: dropped" in out and "Sensitivity scan data that failed the sync or checksum check" in out
    assert "Traceback" not in out, out


@pytest.mark.parametrize("mode", ["Stability", "DenseBoost"])
def test_other_ultra_and_dense_modes_match_the_room(mode: str, rig: Rig) -> None:
    a3 = rig.device(EmulatedA3())
    info = next(m for m in A3_MODES if m.name == mode)
    node = rig.node("rplidar_a3_modes")
    scans = rig.collect(node, "/scan", LaserScan)
    proc = rplidar(rig, f"_serial_port:={a3.path}", "_angle_compensate:=true", f"_scan_mode:={mode}")
    scans.wait_count(3, timeout=30)
    assert a3.working_mode == info.id
    multiple = compensate_multiple(info.us_q8 >> 8)
    check_room(scans.items[-1], a3.mode_samples(info.ans_type), multiple)
    out = rig.stop(proc)
    assert f"current scan mode: {mode}, max_distance: 25.0 m, Point number: 10.0K" in out, out
    assert "Traceback" not in out, out


def test_the_a3_lists_its_modes_when_asked_for_one_it_lacks(rig: Rig) -> None:
    a3 = rig.device(EmulatedA3())
    proc = rplidar(rig, f"_serial_port:={a3.path}", "_scan_mode:=HighSpeed")
    out = rig.read_until(proc, "Can not start scan: 80008001!")  # and it stays up, as rplidar_ros
    assert proc.poll() is None
    out += rig.stop(proc)
    assert "scan mode `HighSpeed' is not supported by lidar, supported modes:" in out, out
    for line in (
        "\tStandard: max_distance: 16.0 m, Point number: 4.0K",
        "\tExpress: max_distance: 16.0 m, Point number: 8.0K",
        "\tBoost: max_distance: 25.0 m, Point number: 16.1K",
        "\tSensitivity: max_distance: 25.0 m, Point number: 16.1K",
        "\tStability: max_distance: 25.0 m, Point number: 10.0K",
    ):
        assert line in out, out
    assert (rp.CONF_SCAN_MODE_COUNT, 0) in a3.conf_queries


def test_an_hq_mode_and_a_garbled_mode_list_are_one_clear_line_each(rig: Rig) -> None:
    hq = (*A3_MODES[:2], ModeInfo(2, "HighQuality", 16000, 25, rp.ANS_TYPE_MEASUREMENT_HQ))
    a3 = rig.device(EmulatedA3(modes=hq))
    out = rig.exit_output(rplidar(rig, f"_serial_port:={a3.path}", "_scan_mode:=HighQuality"))
    assert (
        "scan mode `HighQuality' streams answers of type 0x83, which this driver does not decode "
        "(it decodes 0x81, 0x82, 0x84 and 0x85)"
    ) in out, out
    garbled = rig.device(EmulatedA3(bad_conf=True))
    out = rig.exit_output(rplidar(rig, f"_serial_port:={garbled.path}"))
    assert (
        "Error, cannot get the scan modes of the lidar: GET_LIDAR_CONF asked for entry 0x70 "
        "and was answered 0x71"
    ) in out, out


def test_rplidar_ros_2_scan_frequency_sizes_the_compensated_scan(rig: Rig) -> None:
    """rplidar_ros 2.x's ``scan_frequency`` (Hz, default 10): the angle-compensated scan has the bins a
    turn at that rate fills (Sensitivity's 16K samples/s at 5 Hz: 8 a degree, 2880 beams, where 1.x's
    fixed 10 Hz gave 4); a frequency that is not a positive number is one clear line."""
    assert (compensate_multiple(62.0), compensate_multiple(62.0, 5.0), compensate_multiple(62.0, 40.0)) == (
        4,
        8,
        1,
    )
    a3 = rig.device(EmulatedA3())
    node = rig.node("rplidar_scan_frequency")
    scans = rig.collect(node, "/scan", LaserScan)
    proc = rplidar(
        rig,
        f"_serial_port:={a3.path}",
        "_angle_compensate:=true",
        "_scan_mode:=Sensitivity",
        "_scan_frequency:=5.0",
    )
    scans.wait_count(3, timeout=30)
    check_room(scans.items[-1], a3.mode_samples(ULTRA), 8)
    out = rig.stop(proc)
    assert "angle_compensate: 8" in out and "Traceback" not in out, out
    out = rig.exit_output(rplidar(rig, f"_serial_port:={a3.path}", "_scan_frequency:=0"))
    assert "Error, scan_frequency must be a number of Hz above 0 (and below 100), got 0" in out, out
