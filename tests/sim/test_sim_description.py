"""A Gazebo robot description (xacro -> URDF with <gazebo> blocks) read into the simulator's RobotModel."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from ninjemys.sim.description.build import DescriptionError, expand_xacro, model_from_description
from ninjemys.sim.robot_model import load_robot_model

PACKAGES = Path(__file__).parent / "packages"
XACRO = PACKAGES / "puzzlebot_gz_test" / "urdf" / "puzzlebot.urdf.xacro"


@pytest.fixture(autouse=True)
def _package_path(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGES))


def _model(**args: str):
    return model_from_description(expand_xacro(str(XACRO), args), str(XACRO))


def test_diff_drive_variant_gives_the_makers_names_and_geometry():
    m = _model()
    assert (m.wheel_radius, m.wheel_separation) == pytest.approx((0.05, 0.19))
    assert (m.left_joint, m.right_joint) == ("wheel_left_joint", "wheel_right_joint")
    # the footprint is the chassis box about base_footprint: corner (-0.11, 0.08); top 0.05 + 0.08
    assert m.body_radius == pytest.approx(math.hypot(0.11, 0.08))
    assert m.body_height == pytest.approx(0.13)
    assert m.color == (0, 0, 255)  # Gazebo/Blue on base_link wins over the URDF's visual colour
    d = m.drive
    assert d.kind == "diff_drive"
    assert (d.command_topic, d.odom_topic, d.odom_frame, d.base_frame) == (
        "/cmd_vel",
        "/odom",
        "odom",
        "base_footprint",
    )
    assert d.publish_odom and not d.publish_odom_tf and d.publish_wheel_joint_state and not d.publish_wheel_tf
    assert d.odometry_source == "world" and d.update_rate == 50.0 and m.odom_rate == 50.0
    assert (d.wheel_separation, d.wheel_radius) == pytest.approx((0.19, 0.05))
    assert m.max_wheel_accel == pytest.approx(1.0 / 0.05)  # wheelAcceleration (m/s^2) at the rim
    assert m.max_wheel_speed == 20.0  # the wheel joint's <limit velocity>
    assert not m.sensor_tf  # robot_state_publisher publishes the links
    assert m.ignored_plugins == []
    # its p3d plugin: the ground truth Gazebo publishes (nothing else: no contact topic)
    gt = m.ground_truth
    assert gt is not None and (gt.topic, gt.frame, gt.body, gt.rate) == (
        "/ground_truth/state",
        "world",
        "base_link",
        50.0,
    )
    assert m.contact_topic is None and m.bumper is None


def test_lidar_turned_by_pi_with_its_beams_angles_and_names():
    laser = _model().laser
    assert laser is not None
    assert laser.beams == 360 and (laser.angle_min, laser.angle_max) == (-3.14159, 3.14159)
    assert (laser.range_min, laser.range_max, laser.range_resolution, laser.noise) == (0.12, 12.0, 0.01, 0.01)
    assert laser.rate == 10.0 and laser.topic == "/scan" and laser.pose.frame == "laser_frame"
    assert laser.gazebo_fields  # libgazebo_ros_laser.so's scan_time 0 and intensities
    assert laser.pose.rpy[2] == pytest.approx(math.pi)
    # base_link is 0.05 above the ground (wheel radius), the lidar 0.11 above base_link
    assert laser.pose.xyz == pytest.approx((-0.03, 0.0, 0.16))
    assert _model(lidar_samples="720").laser.beams == 720


def test_camera_size_topics_and_frames():
    cam = _model().camera
    assert cam is not None
    assert (cam.width, cam.height, cam.rate) == (640, 480, 30.0)
    assert cam.hfov == pytest.approx(math.degrees(1.3962634))
    assert (cam.image_topic, cam.info_topic) == ("/camera/image_raw", "/camera/camera_info")
    assert cam.frame == "camera_link_optical" and cam.pose.frame == "camera_link"
    assert cam.depth_topic is None  # a plain camera plugin has no depth stream
    assert cam.pose.xyz == pytest.approx((0.06, 0.0, 0.12))
    imu = _model().imu
    assert imu is not None and imu.topic == "/imu" and imu.pose.frame == "base_link" and imu.rate == 100.0


def test_publish_odom_tf_and_plugin_wheel_separation_come_from_the_xacro_args():
    m = _model(publish_odom_tf="true", plugin_wheel_separation="0.38")
    assert m.drive.publish_odom_tf
    # the plugin converts cmd_vel with its own separation, the body turns on the URDF's:
    # w_actual = w_cmd * plugin_sep / urdf_sep, as in Gazebo
    assert m.drive.wheel_separation == pytest.approx(0.38) and m.wheel_separation == pytest.approx(0.19)


def test_publish_tf_false_silences_odometry_and_its_tf():
    g = (
        '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"><leftJoint>jl</leftJoint>'
        "<rightJoint>jr</rightJoint><publishTf>0</publishTf><publishOdomTF>true</publishOdomTF></plugin></gazebo>"
    )
    d = model_from_description(_urdf(g), "bot.urdf").drive
    assert not d.publish_odom and not d.publish_odom_tf
    assert d.odometry_source == "world" and d.wheel_separation == 0.34  # the plugin's defaults


def test_ros_control_variant():
    m = _model(control="ros_control")
    assert m.drive.kind == "ros_control"
    assert m.drive.controller_namespace == "/" and m.drive.robot_param == "robot_description"
    assert not m.drive.publish_odom and not m.drive.publish_odom_tf
    assert (m.left_joint, m.right_joint) == ("wheel_left_joint", "wheel_right_joint")
    assert m.laser is not None and m.camera is not None
    assert m.control_joints == {"wheel_left_joint": "left", "wheel_right_joint": "right"}
    text = expand_xacro(str(XACRO), {"control": "ros_control"})
    # spawn_model -robot_namespace pb2 moves the controller_manager (and every plugin) under /pb2
    assert model_from_description(text, "x", robot_namespace="pb2").drive.controller_namespace == "/pb2"


def test_load_robot_model_expands_xacro_and_takes_a_robot_namespace():
    m = load_robot_model(str(XACRO), robot_namespace="pb1")
    assert m.drive.command_topic == "/pb1/cmd_vel" and m.laser.topic == "/pb1/scan"
    assert m.camera.image_topic == "/pb1/camera/image_raw" and m.imu.topic == "/pb1/imu"
    # the plugins resolve their frames with the namespace as tf_prefix, as Gazebo's do
    assert (m.drive.odom_frame, m.drive.base_frame) == ("pb1/odom", "pb1/base_footprint")
    assert m.laser.pose.frame == "pb1/laser_frame" and m.camera.frame == "pb1/camera_link_optical"
    assert m.imu.pose.frame == "base_link"  # gazebo_ros_imu_sensor publishes frameName as given


def _urdf(gazebo: str, extra_links: str = "") -> str:
    return f"""<?xml version="1.0"?>
<robot name="bot">
  <link name="base_link">
    <collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.2" length="0.2"/></geometry></collision>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry><material name="red"><color rgba="1 0 0 1"/></material></visual>
  </link>
  <link name="l"><collision><geometry><cylinder radius="0.07" length="0.02"/></geometry></collision></link>
  <link name="r"><collision><geometry><cylinder radius="0.07" length="0.02"/></geometry></collision></link>
  <joint name="jl" type="continuous"><parent link="base_link"/><child link="l"/><origin xyz="0 0.15 0.07" rpy="-1.5708 0 0"/></joint>
  <joint name="jr" type="continuous"><parent link="base_link"/><child link="r"/><origin xyz="0 -0.15 0.07" rpy="-1.5708 0 0"/></joint>
  {extra_links}
  {gazebo}
</robot>"""


def test_no_drive_plugin_is_passive_with_a_warning():
    m = model_from_description(_urdf(""), "bot.urdf")
    assert m.drive.kind == "none" and not m.drive.publish_odom and not m.drive.publish_odom_tf
    assert any("no drive plugin" in w and "libgazebo_ros_diff_drive.so" in w for w in m.warnings)
    assert m.laser is None and m.camera is None and m.imu is None
    assert m.color == (255, 0, 0)  # the URDF visual's colour when Gazebo names none
    assert m.wheel_separation == pytest.approx(0.3) and m.wheel_radius == pytest.approx(0.07)
    # the body: cylinder r=0.2 from z=0 to 0.2 in base_link, whose origin is at the wheel axles (0.07 up)
    assert m.body_radius == pytest.approx(0.2) and m.body_height == pytest.approx(0.2)
    # the same URDF read by our own rules keeps the PuzzleBot's drive
    assert load_robot_model(_urdf("<!-- -->"), gazebo=False).drive.kind == "puzzlebot"


def test_unknown_plugins_listed_once_and_sensor_without_plugin_warned():
    g = """<gazebo><plugin name="a" filename="libfoo.so"/></gazebo>
           <gazebo><plugin name="b" filename="libfoo.so"/><plugin name="c" filename="libbar.so"/></gazebo>
           <gazebo reference="base_link"><sensor type="ray" name="bare"><ray/></sensor></gazebo>"""
    m = model_from_description(_urdf(g), "bot.urdf")
    assert m.ignored_plugins == ["libfoo.so", "libbar.so"]
    assert any("sensor bare (ray) on link base_link has no ROS plugin" in w for w in m.warnings)


def test_skid_steer_gpu_laser_kinect_and_imu_model_plugin():
    g = """<gazebo><plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so">
             <robotNamespace>/husky</robotNamespace><updateRate>20</updateRate>
             <leftFrontJoint>jl</leftFrontJoint><rightFrontJoint>jr</rightFrontJoint>
             <leftRearJoint>jl</leftRearJoint><rightRearJoint>jr</rightRearJoint>
             <wheelSeparation>0.3</wheelSeparation><wheelDiameter>0.14</wheelDiameter>
             <robotBaseFrame>base_link</robotBaseFrame></plugin>
             <plugin name="imu" filename="libgazebo_ros_imu.so"><bodyName>base_link</bodyName>
             <topicName>imu/data</topicName><updateRate>50</updateRate><gaussianNoise>0.02</gaussianNoise></plugin></gazebo>
           <gazebo reference="base_link"><sensor type="gpu_ray" name="lidar"><pose>0.1 0 0.2 0 0 0</pose>
             <update_rate>40</update_rate><ray><scan><horizontal><samples>720</samples><resolution>1</resolution>
             <min_angle>-2.35619</min_angle><max_angle>2.35619</max_angle></horizontal></scan>
             <range><min>0.1</min><max>30</max></range></ray>
             <plugin name="g" filename="libgazebo_ros_gpu_laser.so"><topicName>front/scan</topicName>
             <frameName>/front_laser</frameName></plugin></sensor>
             <sensor type="depth" name="kinect"><camera><horizontal_fov>1.0</horizontal_fov>
             <image><width>160</width><height>120</height></image><clip><near>0.05</near><far>8</far></clip></camera>
             <plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>kinect</cameraName>
             <imageTopicName>rgb/image_raw</imageTopicName><cameraInfoTopicName>rgb/camera_info</cameraInfoTopicName>
             <depthImageTopicName>depth/image_raw</depthImageTopicName>
             <frameName>kinect_optical</frameName><pointCloudCutoffMax>4.0</pointCloudCutoffMax>
             <hackBaseline>0.07</hackBaseline></plugin></sensor></gazebo>"""
    m = model_from_description(_urdf(g), "bot.urdf")
    d = m.drive
    assert d.kind == "skid_steer" and d.command_topic == "/husky/cmd_vel" and d.odom_topic == "/husky/odom"
    assert not d.publish_odom_tf  # broadcastTF defaults to false in the skid steer plugin
    assert d.base_frame == "husky/base_link" and d.odom_frame == "husky/odom" and m.odom_rate == 20.0
    laser = m.laser
    assert laser.beams == 720 and laser.topic == "/front/scan" and laser.pose.frame == "front_laser"
    assert laser.rate == 40.0 and laser.range_max == 30.0
    assert laser.gazebo_fields  # scan_time 0 and an intensity per ray, as gazebo_ros_gpu_laser publishes
    assert laser.pose.xyz == pytest.approx(
        (0.1, 0.0, 0.2)
    )  # base_link is at the ground (wheels r=0.07 at 0.07)
    cam = m.camera
    assert (cam.width, cam.height, cam.depth_max) == (160, 120, 4.0)
    assert cam.hack_baseline == 0.07  # CameraInfo P[3] = -fx * 0.07, as gazebo_ros_camera_utils
    assert cam.image_topic == "/kinect/rgb/image_raw" and cam.depth_topic == "/kinect/depth/image_raw"
    assert cam.depth_info_topic == "/kinect/depth/camera_info" and cam.frame == "kinect_optical"
    assert m.imu.topic == "/imu/data" and m.imu.rate == 50.0 and m.imu.gyro_noise == 0.02
    depth_camera = model_from_description(
        _urdf(g.replace("libgazebo_ros_openni_kinect", "libgazebo_ros_depth_camera")), "b"
    )
    assert depth_camera.camera.depth_topic == "/kinect/depth/image_raw"


@pytest.mark.parametrize(
    ("gazebo", "pattern"),
    [
        (
            '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">\n'
            "<leftJoint>jl</leftJoint><rightJoint>jr</rightJoint>\n<wheelSeparation>wide</wheelSeparation></plugin></gazebo>",
            r"bot\.urdf:\d+: <wheelSeparation>: plugin dd \(libgazebo_ros_diff_drive\.so\): 'wide' is not a number",
        ),
        (
            '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"><leftJoint>nope</leftJoint></plugin></gazebo>',
            r"bot\.urdf:\d+: <leftJoint>: .*joint 'nope' is not in the robot",
        ),
        (
            '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"><leftJoint>jl</leftJoint>'
            "<rightJoint>jr</rightJoint><publishOdomTF>maybe</publishOdomTF></plugin></gazebo>",
            r"<publishOdomTF>: .*'maybe' is not a boolean",
        ),
        (
            '<gazebo reference="base_link"><sensor type="ray" name="s"><ray><scan><horizontal><samples>-3</samples>'
            '</horizontal></scan><range><max>5</max></range></ray><plugin filename="libgazebo_ros_laser.so"/></sensor></gazebo>',
            r"<ray/scan/horizontal/samples>: sensor s \(ray\): must be > 0, got -3",
        ),
        (
            '<gazebo reference="base_link"><sensor type="ray" name="s"><ray><range><min>5</min><max>2</max></range></ray>'
            '<plugin filename="libgazebo_ros_laser.so"/></sensor></gazebo>',
            r"<ray/range/min>: sensor s \(ray\): range min 5 is not below max 2",
        ),
        (
            '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>jl</left_joint>'
            "</plugin></gazebo>",
            r"<leftJoint>: .*joint 'left_joint' is not in the robot \(<left_joint> is the ROS 2 plugin's parameter",
        ),
        (
            '<gazebo reference="nolink"><material>Gazebo/Red</material></gazebo>',
            r"<gazebo>: reference 'nolink' names no link",
        ),
        (
            '<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"/></gazebo>',
            r"<plugin>: plugin i \(libgazebo_ros_imu\.so\): <bodyName> is required",
        ),
    ],
)
def test_malformed_plugin_parameters_name_file_line_element_and_reason(gazebo: str, pattern: str):
    with pytest.raises(DescriptionError, match=pattern):
        model_from_description(_urdf(gazebo), "bot.urdf")


def test_line_numbers_point_at_the_element():
    text = _urdf(
        '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">\n'
        "<leftJoint>jl</leftJoint><rightJoint>jr</rightJoint>\n\n<wheelDiameter>0</wheelDiameter></plugin></gazebo>"
    )
    line = next(i for i, s in enumerate(text.splitlines(), 1) if "<wheelDiameter>" in s)
    with pytest.raises(DescriptionError) as err:
        model_from_description(text, "bot.urdf")
    assert re.match(rf"bot\.urdf:{line}: <wheelDiameter>: .*must be > 0, got 0$", str(err.value))


def test_malformed_xml_and_geometry():
    with pytest.raises(DescriptionError, match=r"bot\.urdf:3: invalid URDF XML"):
        model_from_description('<robot name="b">\n<link name="a">\n</robot>', "bot.urdf")
    bad = _urdf("<gazebo/>").replace('radius="0.2"', 'radius="big"')
    with pytest.raises(
        DescriptionError, match=r"bot\.urdf:\d+: <cylinder>: radius='big' is not 1 finite number"
    ):
        model_from_description(bad, "bot.urdf")
    with pytest.raises(DescriptionError, match="joint .left_joint. is not in the robot"):
        model_from_description(
            '<robot name="b"><link name="a"/><gazebo><plugin name="d" filename="libgazebo_ros_diff_drive.so">'
            "</plugin></gazebo></robot>",
            "bot.urdf",
        )


_ARM = """<robot name="arm">
  <link name="world"/>
  <joint name="fixed" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="base"><collision><origin xyz="0 0 0.5"/><geometry><box size="0.1 0.1 1"/></geometry></collision></link>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0.1 0.95"/><axis xyz="0 1 0"/></joint>
  <link name="upper"><collision><origin xyz="0 0 0.45"/><geometry><box size="0.1 0.1 1"/></geometry></collision></link>
  <joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/>
    <origin xyz="0 0.1 0.9"/><axis xyz="0 1 0"/></joint>
  <link name="fore"><collision><origin xyz="0 0 0.45"/><geometry><box size="0.1 0.1 1"/></geometry></collision></link>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="shoulder"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="m1"/></transmission>
  <transmission name="t2"><type>transmission_interface/SimpleTransmission</type>
    <joint name="elbow"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="m2"/></transmission>
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so"/></gazebo>
</robot>"""


def test_an_arm_under_ros_control_spawns_without_wheels():
    """RRBot's pattern (gazebo_ros_demos): continuous arm joints with box links under gazebo_ros_control.
    Gazebo spawns it; its joints are no wheels (only a round collision rolls), so the base stays put and
    ros_control exposes the joints without a side, with one warning saying so."""
    m = model_from_description(_ARM, "arm.urdf")
    assert m.drive.kind == "ros_control"
    assert (m.left_joint, m.right_joint) == ("", "")
    assert m.control_joints == {"shoulder": "", "elbow": ""}
    assert any("no two continuous joints with a cylinder or sphere collision" in w for w in m.warnings)
    # a wheeled ros_control robot still finds its round wheels among other continuous joints
    wheeled = _ARM.replace(
        '<link name="fore"><collision><origin xyz="0 0 0.45"/><geometry><box size="0.1 0.1 1"/>',
        '<link name="fore"><collision><origin xyz="0 0 0.45"/><geometry><cylinder radius="0.05" length="0.02"/>',
    ).replace(
        "</robot>",
        '<joint name="right" type="continuous"><parent link="base"/><child link="rw"/>'
        '<origin xyz="0 -0.1 0.05"/><axis xyz="0 1 0"/></joint>'
        '<link name="rw"><collision><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision></link>'
        "</robot>",
    )
    w = model_from_description(wheeled, "wheeled.urdf")
    assert {w.left_joint, w.right_joint} == {"elbow", "right"} and w.wheel_radius == 0.05


def test_mutated_descriptions_give_description_errors_and_nothing_else():
    """Random damage to the expanded description (cut, inserted and swapped text) never escapes as
    anything but a DescriptionError: a simulator that spawns it logs one line and keeps running."""
    import random

    text = expand_xacro(str(XACRO))
    rng = random.Random(23)
    tokens = ["-1", "0", "nan", "abc", "", "1e400", "<", "&", '"', "</gazebo>", "true", "3 4"]
    for _ in range(400):
        s = list(text)
        for _ in range(rng.randint(1, 4)):
            k = rng.randrange(len(s))
            op = rng.random()
            if op < 0.4:
                del s[k : k + rng.randint(1, 20)]
            elif op < 0.8:
                s.insert(k, rng.choice(tokens))
            else:
                j = rng.randrange(len(s))
                s[k], s[j] = s[j], s[k]
        try:
            model_from_description("".join(s), "f.urdf")
        except DescriptionError:
            pass


@pytest.mark.ros1
@pytest.mark.parametrize("control", ["gazebo", "ros_control"])
def test_debians_urdfdom_reads_the_expanded_test_package(tmp_path: Path, control: str):
    """The description is a real URDF: Debian's check_urdf (liburdfdom) parses it, with the tree we read."""
    import shutil
    import subprocess

    if shutil.which("check_urdf", path="/usr/bin") is None:
        pytest.skip("needs Debian's liburdfdom-tools")
    urdf = tmp_path / "puzzlebot.urdf"
    urdf.write_text(expand_xacro(str(XACRO), {"control": control}))
    out = subprocess.run(["/usr/bin/check_urdf", str(urdf)], capture_output=True, text=True, timeout=30)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "robot name is: puzzlebot" in out.stdout
    assert "root Link: base_footprint has 1 child(ren)" in out.stdout
    for link in ("wheel_left_link", "wheel_right_link", "laser_frame", "camera_link_optical", "caster_link"):
        assert f"child(1):  {link}" in out.stdout or f"  {link}" in out.stdout
