"""The simulator's parts without a node: message builders, scan geometry, the stepper's schedule,
the node's sensor parameters, and Gazebo's frame arithmetic."""

from __future__ import annotations

import math
import os
import threading
import time

import numpy as np
import pytest

from ninjemys.sim import messages
from ninjemys.sim.gazebo_api import compose, relative
from ninjemys.sim.puzzlebot_node import configure_model
from ninjemys.sim.robot_model import LaserSpec, SensorPose, load_robot_model
from ninjemys.sim.simcore import Simulation, SpawnError, scan_angles
from ninjemys.sim.stepper import Due, StepLock, Stepper
from ninjemys.sim.world2d import Obstacle, World, box_outline


def laser(beams: int, amin: float = -math.pi, amax: float | None = None) -> LaserSpec:
    return LaserSpec(
        SensorPose("laser", (0.0, 0.0, 0.1), (0.0, 0.0, 0.0)), beams=beams, angle_min=amin, angle_max=amax
    )


def test_scan_angles_full_turn_and_gazebo_span() -> None:
    assert scan_angles(laser(360)) == pytest.approx((-math.pi, -math.pi + 359 * math.pi / 180, math.pi / 180))
    # gazebo_ros_laser: samples spread over [min_angle, max_angle], both ends included
    amin, amax, inc = scan_angles(laser(720, -math.pi / 2, math.pi / 2))
    assert (amin, amax) == (-math.pi / 2, math.pi / 2)
    assert inc == pytest.approx(math.pi / 719)
    assert scan_angles(laser(1))[2] == pytest.approx(2 * math.pi)
    assert scan_angles(laser(1, 0.0, 0.0))[2] == 0.0


def test_laser_scan_message_uses_the_spec() -> None:
    spec = laser(1147, -2.0, 2.0)
    msg = messages.laser_scan(
        messages.stamp_of(150, 0.01), "base_scan", spec, np.ones(1147, dtype=np.float32)
    )
    assert msg.header.frame_id == "base_scan"
    assert (msg.header.stamp.secs, msg.header.stamp.nsecs) == (1, 500_000_000)
    assert msg.angle_min == -2.0 and msg.angle_max == 2.0
    assert msg.angle_increment == pytest.approx(4.0 / 1146)
    assert len(msg.ranges) == 1147


def test_a_gazebo_laser_scan_has_the_plugins_timing_and_intensity_fields() -> None:
    # gazebo_ros_laser / gpu_laser: time_increment 0 and scan_time 0 (an instantaneous simulated scan),
    # one intensity per ray (the ray sensor's retro value, 0 here); a driver-like laser keeps its period
    ranges = np.full(360, 2.0, dtype=np.float32)
    spec = laser(360)
    spec.rate = 5.0
    driver = messages.laser_scan(messages.stamp_of(0, 0.01), "laser", spec, ranges)
    assert (driver.time_increment, driver.scan_time, len(driver.intensities)) == (0.0, pytest.approx(0.2), 0)
    spec.gazebo_fields = True
    gz = messages.laser_scan(messages.stamp_of(0, 0.01), "laser", spec, ranges)
    assert (gz.time_increment, gz.scan_time) == (0.0, 0.0)
    assert list(gz.intensities) == [0.0] * 360
    back = type(gz)().deserialize(gz.serialize_to_bytes())  # the wire form carries the intensities
    assert back.scan_time == 0.0 and len(back.intensities) == 360


def test_scan_of_a_half_turn_laser_sees_what_is_ahead_only() -> None:
    """Beams from -pi/2 to pi/2: a box behind the robot is invisible, one ahead is seen."""
    model = load_robot_model("puzzlebot")
    model.laser.beams, model.laser.angle_min, model.laser.angle_max = 181, -math.pi / 2, math.pi / 2
    model.laser.noise = 0.0
    world = World("t", [Obstacle("ahead", "box", box_outline(2.0, 0.0, 0.2, 0.2), 0.5, (1, 2, 3))])
    sim = Simulation(world)
    r = sim.add_robot("r", model, 0.0, 0.0, 0.0)
    ranges = sim.scan(r)
    assert len(ranges) == 181
    assert ranges[90] == pytest.approx(
        2.0 - 0.1 - model.laser.pose.xyz[0], abs=0.02
    )  # the middle beam: ahead
    r.yaw = math.pi  # turned round: the box is behind, out of the half turn
    assert not np.isfinite(sim.scan(r)[90]) or sim.scan(r)[90] > 10


def test_odometry_and_transforms() -> None:
    stamp = messages.stamp_of(3, 0.5)
    odom = messages.odometry(
        stamp, "odom", "base_footprint", (1.0, 2.0, math.pi / 2), (0.3, 0.1), (0.1, 0, 0.2, 0)
    )
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    assert odom.pose.pose.orientation.z == pytest.approx(math.sqrt(0.5))
    cov = list(odom.pose.covariance)
    assert cov[0] == pytest.approx(1e-4 + 0.002) and cov[35] == pytest.approx(1e-4 + 0.001) and cov[14] == 1e6
    truth = messages.odometry(stamp, "map", "base_link", (0.0, 0.0, 0.0), (0.0, 0.0))
    assert list(truth.pose.covariance) == [0.0] * 36
    model = load_robot_model("puzzlebot")
    model.drive.base_frame = "base_footprint"
    model.camera.frame, model.camera.depth_topic = "camera_rgb_optical", None
    tfs = messages.static_transforms(model, "r1/", stamp)
    pairs = {(t.header.frame_id, t.child_frame_id) for t in tfs}
    assert ("r1/base_footprint", "r1/laser") in pairs
    assert ("r1/camera_link", "r1/camera_rgb_optical") in pairs
    assert not any("depth" in child for _, child in pairs)  # a colour-only camera has no depth frame


def test_odometry_refreshed_in_place_is_a_fresh_message() -> None:
    """The node builds its odometry message once and refreshes it per sample: the bytes are those of
    a message built for that sample (noise covariance, frames, stamp, pose and twist)."""
    from ninjemys.rostime import Time

    alpha = (0.2, 0.0, 0.1, 0.0)
    kept = messages.odometry(Time(0, 0), "odom", "base_link", (0.0, 0.0, 0.0), (0.0, 0.0), alpha)
    for secs, pose, twist in ((1, (1.0, 2.0, 0.3), (0.1, 0.2)), (2, (-1.5, 0.25, -3.1), (-0.4, 1.9))):
        fresh = messages.odometry(Time(secs, 500), "odom", "base_link", pose, twist, alpha)
        same = messages.odometry_into(kept, Time(secs, 500), pose, twist)
        assert same is kept
        assert b"".join(kept.frame_parts()[1]) == b"".join(fresh.frame_parts()[1])


def test_transform_and_joint_states_refreshed_in_place_are_fresh_messages() -> None:
    """The odom -> base transform and the wheels' joint_states are built once per robot and refreshed
    per sample: the bytes are those of messages built for that sample."""
    from ninjemys.rostime import Time
    from ninjemys.tf2.math import quaternion_from_yaw

    tf = messages.transform(Time(0, 0), "odom", "base_footprint", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    js = messages.joint_state(Time(0, 0), ["left", "right"], [0.0, 0.0], [0.0, 0.0])
    for secs, x, y, yaw in ((1, 1.0, 2.0, 0.3), (2, -1.5, 0.25, -3.1)):
        q = quaternion_from_yaw(yaw)
        fresh = messages.transform(Time(secs, 7), "odom", "base_footprint", (x, y, 0.0), q)
        assert messages.transform_into(tf, Time(secs, 7), (x, y, 0.0), q) is tf
        assert b"".join(tf.frame_parts()[1]) == b"".join(fresh.frame_parts()[1])
        fresh_js = messages.joint_state(Time(secs, 7), ["left", "right"], [x, y], [yaw, -yaw])
        assert messages.joint_state_into(js, Time(secs, 7), [x, y], [yaw, -yaw]) is js
        assert b"".join(js.frame_parts()[1]) == b"".join(fresh_js.frame_parts()[1])


def test_camera_messages() -> None:
    model = load_robot_model("puzzlebot")
    rgb = np.zeros((4, 6, 3), dtype=np.uint8)
    img = messages.rgb_image(messages.stamp_of(0, 0.01), "cam", rgb)
    assert (img.width, img.height, img.step, img.encoding) == (6, 4, 18, "rgb8")
    depth = messages.depth_image(messages.stamp_of(0, 0.01), "d", np.full((4, 6), 1500, dtype=np.uint16))
    assert depth.encoding == "16UC1" and bytes(depth.data[:2]) == (1500).to_bytes(2, "little")
    info = messages.camera_info(messages.stamp_of(0, 0.01), "cam", model.camera, (100.0, 100.0, 160.0, 120.0))
    assert info.K[0] == 100.0 and info.width == model.camera.width
    assert info.P[3] == 0.0
    # gazebo_ros_camera's <hackBaseline> 0.07 (the Gazebo tutorials' camera, a stereo pair's right eye)
    model.camera.hack_baseline = 0.07
    info = messages.camera_info(messages.stamp_of(0, 0.01), "cam", model.camera, (100.0, 100.0, 160.0, 120.0))
    assert info.P[3] == pytest.approx(-7.0) and info.P[:3] == [100.0, 0.0, 160.0]


def test_configure_model_from_parameters() -> None:
    model = load_robot_model("puzzlebot")
    given = {
        "publish_odom_tf": False,
        "odom_topic": "wheel_odom",
        "scan_topic": "base_scan",
        "scan_beams": 720,
        "scan_angle_min": -1.5,
        "scan_angle_max": 1.5,
        "image_topic": "camera/image_raw",
        "camera_info_topic": "camera/camera_info",
        "imu_topic": "imu/data",
        "cmd_vel_topic": "mobile_base/cmd_vel",
    }
    configure_model(model, lambda key, default, _kind: given.get(key, default), lambda key: key[1:] in given)
    assert not model.drive.publish_odom_tf and model.drive.publish_odom
    assert model.drive.odom_topic == "wheel_odom" and model.drive.command_topic == "mobile_base/cmd_vel"
    assert (model.laser.topic, model.laser.beams, model.laser.angle_min, model.laser.angle_max) == (
        "base_scan",
        720,
        -1.5,
        1.5,
    )
    assert model.camera.image_topic == "camera/image_raw" and model.camera.info_topic == "camera/camera_info"
    assert model.imu.topic == "imu/data"
    untouched = load_robot_model("puzzlebot")
    configure_model(untouched, lambda _k, default, _kind: default, lambda _k: False)
    assert untouched.laser.angle_max is None and untouched.camera.image_topic == "camera/color/image_raw"


def test_due_fires_on_schedule_without_bursts() -> None:
    due = Due(0.1, 0.0)
    fired = [t for t in (0.0, 0.05, 0.1, 0.15, 0.2, 1.0, 1.05, 1.1) if due.fire(t)]
    # after a gap (a pause): one catch-up at most, not the eight periods missed
    assert fired == [0.0, 0.1, 0.2, 1.0, 1.05, 1.1]


def test_stepper_pauses_and_counts() -> None:
    steps: list[int] = []
    clock = {"t": 0.0}

    def step() -> None:
        clock["t"] += 0.01
        steps.append(1)

    errors: list[Exception] = []
    stepper = Stepper(step, lambda: clock["t"], 0.01, 0.0, StepLock(), errors.append, name="test-stepper")
    stepper.set_paused(True)
    stepper.start()
    time.sleep(0.1)
    assert not steps
    stepper.set_paused(False)
    deadline = time.monotonic() + 5
    while len(steps) < 50 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert stepper.stop()
    assert len(steps) >= 50 and stepper.stepped == pytest.approx(0.01 * len(steps))
    assert "simulated" in stepper.summary() and not errors
    assert not any(t.name == "test-stepper" for t in threading.enumerate())


def test_a_paced_stepper_behind_its_rate_lets_a_waiter_in_at_the_next_step() -> None:
    """A simulator paced at real time whose steps take longer than they simulate (a loaded
    machine) steps back to back: a service waiting for the lock gets it after the step under way,
    not whenever the stepping thread happens to lose the race for it (both threads on one CPU,
    where the stepping thread used to win it step after step)."""
    lock = StepLock()
    count = {"n": 0}

    def step() -> None:  # 20 ms of CPU for 10 ms of simulated time
        count["n"] += 1
        end = time.thread_time() + 0.02
        while time.thread_time() < end:
            pass

    errors: list[Exception] = []
    cpu = min(os.sched_getaffinity(0))
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {cpu})  # this thread, and the threads it starts, on one CPU
    try:
        stepper = Stepper(step, lambda: count["n"] * 0.01, 0.01, 1.0, lock, errors.append)
        stepper.start()
        try:
            waits = []
            for _ in range(10):
                time.sleep(0.03)
                asked = count["n"]
                with lock:
                    waits.append(count["n"] - asked)
        finally:
            stepper.stop()
    finally:
        os.sched_setaffinity(0, before)
    assert not errors and count["n"] >= 10
    assert max(waits) <= 1, waits  # the step under way finishes, then the waiter is in


def test_a_failing_step_is_reported_and_stepping_goes_on() -> None:
    count = {"n": 0}

    def step() -> None:
        count["n"] += 1
        if count["n"] == 2:
            raise RuntimeError("boom")

    errors: list[Exception] = []
    stepper = Stepper(step, lambda: count["n"] * 0.01, 0.01, 0.0, StepLock(), errors.append)
    stepper.start()
    deadline = time.monotonic() + 5
    while count["n"] < 10 and time.monotonic() < deadline:
        time.sleep(0.01)
    stepper.stop()
    assert [str(e) for e in errors] == ["boom"] and count["n"] >= 10


def test_place_robot_and_move_obstacle_refuse_overlaps() -> None:
    world = World("t", [Obstacle("crate", "box", box_outline(2.0, 0.0, 0.4, 0.4), 0.5, (1, 2, 3))])
    sim = Simulation(world)
    sim.add_robot("r", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0)
    with pytest.raises(SpawnError, match="inside 'crate'"):
        sim.place_robot("r", 2.0, 0.0, 0.0)
    sim.place_robot("r", -1.0, 1.0, 0.5)
    assert (sim.robots["r"].x, sim.robots["r"].y) == (-1.0, 1.0)
    with pytest.raises(SpawnError, match="overlap robot"):
        sim.move_obstacle("crate", -1.0, 1.0, 0.0)
    sim.move_obstacle("crate", 3.0, -2.0, math.pi / 4)
    x, y, yaw = sim.obstacle_pose("crate")
    assert (x, y, yaw) == pytest.approx((3.0, -2.0, math.pi / 4))
    assert sim.clearance(3.0, -2.0 + 0.5)[1] == "crate"


def test_relative_and_compose_are_inverse() -> None:
    ref = (1.0, 2.0, 0.1, math.pi / 3)
    pose = (4.0, -1.0, 0.3, -0.5)
    assert compose(ref, relative(pose, ref)) == pytest.approx(pose)
    assert relative((1.0, 3.0, 0.0, 0.0), (1.0, 2.0, 0.0, math.pi / 2))[:2] == pytest.approx((1.0, 0.0))
