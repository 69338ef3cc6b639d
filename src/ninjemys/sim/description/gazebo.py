"""The ``<gazebo>`` blocks of a URDF: which plugins drive the robot and which sensors publish what.

Each reader takes the parameters by the names, defaults and meanings of gazebo_ros_pkgs' plugins
(Noetic): a parameter that is absent takes the plugin's default, one that does not parse is a
DescriptionError naming file, line, element and reason. A sensor without a ROS plugin publishes
nothing in Gazebo, so it is left out here too; a plugin we do not simulate is listed once.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from ninjemys.robot.kinematics import rpy_matrix
from ninjemys.sim.description.geometry import Geometry, Transform, compose, rpy_of
from ninjemys.sim.description.params import Reader
from ninjemys.sim.description.xmltree import Document
from ninjemys.sim.gazebo_materials import stock_colour
from ninjemys.sim.robot_model import (
    BumperSpec,
    CameraSpec,
    DriveSpec,
    GroundTruthSpec,
    ImuSpec,
    LaserSpec,
    SensorPose,
)

DIFF_DRIVE = "libgazebo_ros_diff_drive.so"
SKID_STEER = "libgazebo_ros_skid_steer_drive.so"
ROS_CONTROL = "libgazebo_ros_control.so"
LASERS = ("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so")
CAMERA = "libgazebo_ros_camera.so"
KINECT = "libgazebo_ros_openni_kinect.so"
DEPTH_CAMERA = "libgazebo_ros_depth_camera.so"  # the same depth parameters as the kinect plugin
IMU_SENSOR = "libgazebo_ros_imu_sensor.so"
IMU_MODEL = "libgazebo_ros_imu.so"
P3D = "libgazebo_ros_p3d.so"
BUMPER = "libgazebo_ros_bumper.so"
DRIVES = (DIFF_DRIVE, SKID_STEER, ROS_CONTROL)


@dataclass
class GazeboConfig:
    """What the ``<gazebo>`` blocks say, ready to be laid over the geometry."""

    drive: DriveSpec | None = None
    left_joint: str | None = None
    right_joint: str | None = None
    wheel_accel: float | None = None  # m/s^2 at the rim; 0 = immediate
    laser: LaserSpec | None = None
    camera: CameraSpec | None = None
    extra_lasers: list[LaserSpec] = field(default_factory=list)
    extra_cameras: list[CameraSpec] = field(default_factory=list)
    imu: ImuSpec | None = None
    ground_truth: GroundTruthSpec | None = None  # a p3d plugin's (Gazebo publishes none without one)
    bumper: BumperSpec | None = None  # a contact sensor's bumper plugin
    #: gazebo_ros_control beside a plugin drive (the ROSbot's skid steer): its controller_manager runs
    #: over the transmissions' joints all the same, so joint_state_controller publishes the wheels
    control: DriveSpec | None = None
    materials: dict[str, tuple[int, int, int]] = field(default_factory=dict)
    ignored: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    unknown_materials: list[str] = field(default_factory=list)  # named once in a warning


def topic(namespace: str, name: str) -> str:
    """A gazebo_ros plugin's topic: ``name`` in a node handle of ``namespace`` (Gazebo runs in /)."""
    if name.startswith("/"):
        return name
    ns = namespace.strip("/")
    return f"/{ns}/{name}" if ns else f"/{name}"


def frame(name: str, namespace: str = "") -> str:
    """A frame id as the plugins publish it: tf::resolve with the robot namespace as tf_prefix
    (``odom`` under robotNamespace ``/pb1`` is ``pb1/odom``); an absolute ``/name`` is kept, less its slash."""
    if name.startswith("/"):
        return name.lstrip("/")
    prefix = namespace.strip("/")
    return f"{prefix}/{name}" if prefix else name


def _namespace(r: Reader, override: str | None) -> str:
    return override if override is not None else r.text("robotNamespace", "")


def read_gazebo(doc: Document, geo: Geometry, robot_namespace: str | None = None) -> GazeboConfig:
    """Every ``<gazebo>`` block of the document; ``robot_namespace`` is spawn_model's -robot_namespace."""
    cfg = GazeboConfig()
    for block in doc.root.findall("gazebo"):
        ref = block.get("reference")
        if ref is not None and ref not in geo.links:
            if ref in geo.joints:
                continue  # joint properties (damping, implicitSpringDamper): physics we do not model
            raise doc.error(block, f"reference '{ref}' names no link of the robot", "gazebo")
        mat = block.find("material")
        if ref is not None and mat is not None and mat.text:
            name = mat.text.strip()
            colour = stock_colour(name)
            if colour is not None:
                cfg.materials[ref] = colour
            elif name not in cfg.unknown_materials:
                # a material of the robot's own scripts (not read from a URDF): drawn in the URDF's colour
                cfg.unknown_materials.append(name)
                cfg.warnings.append(
                    f"{doc.source}:{doc.line(mat)}: <gazebo reference='{ref}'> material '{name}' is not one of"
                    " Gazebo's stock materials: the link keeps its URDF colour"
                )
        for plugin in block.findall("plugin"):
            _model_plugin(doc, plugin, geo, cfg, robot_namespace)
        for sensor in block.findall("sensor"):
            _sensor(doc, sensor, geo, ref or geo.root, cfg, robot_namespace)
    return cfg


def _ros_control(r: Reader, label: str, cfg: GazeboConfig, ns_override: str | None) -> DriveSpec:
    """gazebo_ros_control's plugin: its controller_manager's namespace, period and robot parameter."""
    ns = _namespace(r, ns_override)
    period = r.number("controlPeriod", 0.0, minimum=0)
    sim_type = r.text("robotSimType", "gazebo_ros_control/DefaultRobotHWSim")
    if sim_type != "gazebo_ros_control/DefaultRobotHWSim":
        cfg.warnings.append(f"{label}: robotSimType {sim_type}: simulated as DefaultRobotHWSim")
    return DriveSpec.silent(
        "ros_control",
        update_rate=(1.0 / period) if period else None,
        controller_namespace=topic(ns, "").rstrip("/") or "/",
        robot_param=r.text("robotParam", "robot_description"),
    )


def _model_plugin(
    doc: Document, plugin: ET.Element, geo: Geometry, cfg: GazeboConfig, ns_override: str | None
) -> None:
    filename = plugin.get("filename", "")
    label = f"plugin {plugin.get('name', '')} ({filename})"
    r = Reader(doc, plugin, label)
    if filename in DRIVES and cfg.drive is not None:
        if cfg.control is None and (filename == ROS_CONTROL) != (cfg.drive.kind == "ros_control"):
            # a plugin drive and gazebo_ros_control, in either order: the plugin drives the wheels,
            # the controller_manager runs beside it
            if filename == ROS_CONTROL:
                cfg.control = _ros_control(r, label, cfg, ns_override)
                return
            cfg.control, cfg.drive = cfg.drive, None  # the plugin drive is read below
        else:
            cfg.warnings.append(
                f"{label}: a second drive plugin; the first one ({cfg.drive.kind}) drives the robot"
            )
            return
    if filename == DIFF_DRIVE:
        ns = _namespace(r, ns_override)
        cfg.drive = DriveSpec(
            kind="diff_drive",
            command_topic=topic(ns, r.text("commandTopic", "cmd_vel")),
            odom_topic=topic(ns, r.text("odometryTopic", "odom")),
            odom_frame=frame(r.text("odometryFrame", "odom"), ns),
            base_frame=frame(r.text("robotBaseFrame", "base_footprint"), ns),
            # publishTf is the plugin's switch for the odometry topic and its TF (its name is historical)
            publish_odom=r.boolean("publishTf", r.boolean("publishOdom", True)),
            publish_odom_tf=r.boolean("publishOdomTF", True) and r.boolean("publishTf", True),
            publish_wheel_tf=r.boolean("publishWheelTF", False),
            publish_wheel_joint_state=r.boolean("publishWheelJointState", False),
            publish_wheel_speeds=False,
            odometry_source=r.choice("odometrySource", "world", ("world", "encoder")),
            update_rate=r.number("updateRate", 100.0, minimum=0) or None,
            wheel_separation=r.number("wheelSeparation", 0.34, positive=True),
            wheel_radius=r.number("wheelDiameter", 0.15, positive=True) / 2,
            joint_states_topic=topic(ns, "joint_states"),
        )
        r.number("wheelTorque", 5.0, minimum=0)  # checked; a kinematic model has no torque limit
        cfg.left_joint = _joint(r, geo, "leftJoint", "left_joint")
        cfg.right_joint = _joint(r, geo, "rightJoint", "right_joint")
        cfg.wheel_accel = r.number("wheelAcceleration", 0.0, minimum=0)
    elif filename == SKID_STEER:
        ns = _namespace(r, ns_override)
        cfg.drive = DriveSpec(
            kind="skid_steer",
            command_topic=topic(ns, r.text("commandTopic", "cmd_vel")),
            odom_topic=topic(ns, r.text("odometryTopic", "odom")),
            odom_frame=frame(r.text("odometryFrame", "odom"), ns),
            base_frame=frame(r.text("robotBaseFrame", "base_footprint"), ns),
            publish_odom=True,
            publish_odom_tf=r.boolean("broadcastTF", False),
            publish_wheel_tf=False,
            publish_wheel_joint_state=False,
            publish_wheel_speeds=False,
            odometry_source="world",
            update_rate=r.number("updateRate", 100.0, minimum=0) or None,
            wheel_separation=r.number("wheelSeparation", 0.4, positive=True),
            wheel_radius=r.number("wheelDiameter", 0.15, positive=True) / 2,
            joint_states_topic=topic(ns, "joint_states"),
        )
        r.number("torque", 5.0, minimum=0)
        cfg.left_joint = _joint(r, geo, "leftFrontJoint", "left_front_joint")
        cfg.right_joint = _joint(r, geo, "rightFrontJoint", "right_front_joint")
        _joint(r, geo, "leftRearJoint", "left_rear_joint")
        _joint(r, geo, "rightRearJoint", "right_rear_joint")
    elif filename == ROS_CONTROL:
        cfg.drive = _ros_control(r, label, cfg, ns_override)
    elif filename == IMU_MODEL:
        body = r.text("bodyName", "")
        if not body:
            raise doc.error(plugin, f"{label}: <bodyName> is required (the IMU's link)", "plugin")
        if body not in geo.links:
            raise doc.error(
                plugin, f"{label}: bodyName '{body}' names no link of the robot", "plugin/bodyName"
            )
        ns = _namespace(r, ns_override)
        offset = _offset(r, "xyzOffsets", "rpyOffsets")
        pose = _sensor_pose(geo, body, offset, frame(r.text("frameName", body)))
        rate = r.number("updateRate", 0.0, minimum=0)
        noise = r.number("gaussianNoise", 0.0, minimum=0)
        if cfg.imu is None:
            cfg.imu = ImuSpec(pose, rate or 100.0, noise, noise, topic(ns, r.text("topicName", body)))
    elif filename == P3D:
        cfg.ground_truth = _p3d(doc, plugin, r, geo, label, ns_override)
    else:
        cfg.ignored.append(filename or plugin.get("name", "<plugin>"))


def _p3d(
    doc: Document, plugin: ET.Element, r: Reader, geo: Geometry, label: str, ns_override: str | None
) -> GroundTruthSpec:
    """gazebo_ros_p3d: a body's true pose on topicName (both required, as the plugin refuses to load
    without them), stamped in frameName (``world`` by default), every updateRate-th of a second."""
    body, name = r.text("bodyName", ""), r.text("topicName", "")
    for tag, value in (("bodyName", body), ("topicName", name)):
        if not value:
            raise doc.error(plugin, f"{label}: <{tag}> is required", f"plugin/{tag}")
    if body not in geo.links:
        raise doc.error(plugin, f"{label}: bodyName '{body}' names no link of the robot", "plugin/bodyName")
    ns = _namespace(r, ns_override)
    return GroundTruthSpec(
        topic(ns, name), frame(r.text("frameName", "world")), body, r.number("updateRate", 0.0, minimum=0)
    )


#: the ROS 2 plugins' names of the ROS 1 parameters, often copied into ROS 1 descriptions by mistake
ROS2_NAMES = {
    "leftJoint": "left_joint",
    "rightJoint": "right_joint",
    "leftFrontJoint": "left_joint",
    "rightFrontJoint": "right_joint",
}


def _joint(r: Reader, geo: Geometry, path: str, default: str) -> str:
    name = r.text(path, default)
    if name not in geo.joints:
        child = r.el.find(path)
        hint = ""
        ros2 = ROS2_NAMES.get(path)
        if child is None and ros2 and r.el.find(ros2) is not None:
            hint = f" (<{ros2}> is the ROS 2 plugin's parameter; ROS 1's gazebo_ros reads <{path}>)"
        raise r.doc.error(
            child if child is not None else r.el, f"{r.label}: joint '{name}' is not in the robot{hint}", path
        )
    return name


def _offset(r: Reader, xyz: str, rpy: str) -> Transform:
    p = r.vector(xyz, 3, (0.0, 0.0, 0.0))
    o = r.vector(rpy, 3, (0.0, 0.0, 0.0))
    return rpy_matrix(*o), (p[0], p[1], p[2])


def _sensor_pose(geo: Geometry, link: str, local: Transform, frame_id: str) -> SensorPose:
    t = compose(geo.pose_of(link), local)
    ground = geo.ground_z()
    xyz = (t[1][0], t[1][1], t[1][2] - ground)
    return SensorPose(frame_id, xyz, rpy_of(t[0]))


def _pose_element(r: Reader) -> Transform:
    six = r.vector("pose", 6, (0.0,) * 6)
    return rpy_matrix(six[3], six[4], six[5]), (six[0], six[1], six[2])


def _sensor(
    doc: Document, sensor: ET.Element, geo: Geometry, link: str, cfg: GazeboConfig, ns_override: str | None
) -> None:
    kind = sensor.get("type", "")
    name = sensor.get("name", kind)
    label = f"sensor {name} ({kind})"
    s = Reader(doc, sensor, label)
    plugin = sensor.find("plugin")
    if plugin is None:
        cfg.warnings.append(f"{label} on link {link} has no ROS plugin: it publishes nothing")
        return
    filename = plugin.get("filename", "")
    p = Reader(doc, plugin, f"{label} plugin {filename}")
    local = _pose_element(s)
    rate = s.number("update_rate", 0.0, minimum=0)
    ns = _namespace(p, ns_override)
    if kind in ("ray", "gpu_ray") and filename in LASERS:
        h = "ray/scan/horizontal/"
        samples = s.integer(h + "samples", 640, positive=True)
        resolution = s.number(h + "resolution", 1.0, positive=True)
        lo = s.number(h + "min_angle", 0.0)
        hi = s.number(h + "max_angle", 0.0)
        if hi < lo:
            raise doc.error(
                sensor.find(h + "max_angle"),
                f"{label}: max_angle {hi:g} is below min_angle {lo:g}",
                h + "max_angle",
            )
        rmin = s.number("ray/range/min", 0.0, minimum=0)
        rmax = s.number("ray/range/max", 0.0, positive=True) if s.has("ray/range/max") else None
        if rmax is None:
            raise doc.error(sensor, f"{label}: <ray><range><max> is required", "sensor")
        if rmin >= rmax:
            raise doc.error(
                sensor.find("ray/range/min"),
                f"{label}: range min {rmin:g} is not below max {rmax:g}",
                "ray/range/min",
            )
        beams = max(1, round(samples * resolution))
        frame_id = frame(p.text("frameName", "/world"), ns)
        if not p.has("frameName"):
            cfg.warnings.append(f"{label}: missing <frameName>, defaults to /world")
        laser = LaserSpec(
            _sensor_pose(geo, link, local, frame_id),
            rate or 10.0,
            beams,
            rmin,
            rmax,
            s.number("ray/noise/stddev", 0.0, minimum=0),
            topic(ns, p.text("topicName", "/world")),
            lo,
            hi,
            range_resolution=s.number("ray/range/resolution", 0.0, minimum=0),
            gazebo_fields=True,
        )
        if cfg.laser is None:
            cfg.laser = laser
        else:  # a second lidar: its own topic, frame and rate
            cfg.extra_lasers.append(laser)
    elif kind in ("camera", "depth") and filename in (CAMERA, KINECT, DEPTH_CAMERA):
        width = s.integer("camera/image/width", 320, positive=True)
        height = s.integer("camera/image/height", 240, positive=True)
        hfov = s.number("camera/horizontal_fov", 1.047, positive=True)
        if hfov >= math.radians(170):
            raise doc.error(
                sensor.find("camera/horizontal_fov"),
                f"{label}: a pinhole camera needs < 170 degrees",
                "camera/horizontal_fov",
            )
        near = s.number("camera/clip/near", 0.1, positive=True)
        far = s.number("camera/clip/far", 100.0, positive=True)
        if near >= far:
            raise doc.error(
                sensor.find("camera/clip/near"),
                f"{label}: clip near {near:g} is not below far {far:g}",
                "camera/clip/near",
            )
        cam_ns = topic(ns, p.text("cameraName", "")).rstrip("/")
        plugin_rate = p.number("updateRate", 0.0, minimum=0)
        frame_id = frame(p.text("frameName", "/world"), ns)
        depth = filename in (KINECT, DEPTH_CAMERA)
        if depth:
            far = min(far, p.number("pointCloudCutoffMax", 5.0, positive=True))
        camera = CameraSpec(
            _sensor_pose(geo, link, local, link),
            plugin_rate or rate or 30.0,
            width,
            height,
            math.degrees(hfov),
            far,
            f"{cam_ns}/{p.text('imageTopicName', 'image_raw')}",
            f"{cam_ns}/{p.text('cameraInfoTopicName', 'camera_info')}",
            frame_id,
            f"{cam_ns}/{p.text('depthImageTopicName', 'depth/image_raw')}" if depth else None,
            f"{cam_ns}/{p.text('depthImageCameraInfoTopicName', 'depth/camera_info')}" if depth else None,
            frame_id,
            hack_baseline=p.number("hackBaseline", 0.0),
        )
        if cfg.camera is None:
            cfg.camera = camera
        else:  # a second camera: its own topics, frame and rate
            cfg.extra_cameras.append(camera)
    elif kind == "imu" and filename == IMU_SENSOR:
        if not p.has("frameName"):
            raise doc.error(
                plugin, f"{label}: <frameName> is required (gazebo_ros_imu_sensor stops without it)", "plugin"
            )
        # no <robotNamespace>: the plugin uses the model's name (spawn_model's -model; the URDF's here)
        given = (
            ns_override
            if ns_override is not None
            else (p.text("robotNamespace", "") if p.has("robotNamespace") else None)
        )
        prefix = f"/{given.strip('/')}" if given is not None else f"/{geo.name}"
        prefix = prefix.rstrip("/")
        if cfg.imu is None:
            noise = p.number("gaussianNoise", 0.0, minimum=0)
            cfg.imu = ImuSpec(
                _sensor_pose(
                    geo,
                    link,
                    compose(local, _offset(p, "xyzOffset", "rpyOffset")),
                    frame(p.text("frameName", "")),
                ),
                p.number("updateRateHZ", 1.0, minimum=0) or rate or 100.0,
                noise,
                noise,
                f"{prefix}/{p.text('topicName', '/imu_data').lstrip('/')}",
            )
    elif kind == "contact" and filename == BUMPER:
        collision = s.text("contact/collision", "")
        if not collision:
            raise doc.error(
                sensor, f"{label}: <contact><collision> names no collision to watch", "sensor/contact"
            )
        cfg.bumper = BumperSpec(
            topic(ns, p.text("bumperTopicName", "bumper_states")),
            frame(p.text("frameName", "world")),
            collision,
            rate,
        )
    else:
        cfg.ignored.append(filename or name)
