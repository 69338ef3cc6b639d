"""Robot descriptions: the editable YAML of ours and the URDF subset, read into one :class:`RobotModel`.

No ROS in here. ``robots/puzzlebot.yaml`` (share/puzzlebot_sim) is the default and the template; a
user's YAML overrides any of its fields (missing ones keep the PuzzleBot's values). A URDF gives the
geometry (body cylinder, wheel radius and separation from the continuous wheel joints, sensor poses
from the fixed joints to ``laser``, ``camera_link`` and ``imu_link``); rates, limits and noise stay the
YAML defaults.
"""

from __future__ import annotations

import copy
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from ninjemys.maps.mapfile import Fields, MapFileError, yaml_lines
from ninjemys.robot.kinematics import Joint, URDFError, parse_urdf
from ninjemys.sim.worlds import ROBOTS_DIR


@dataclass
class SensorPose:
    frame: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]


@dataclass
class LaserSpec:
    pose: SensorPose
    rate: float = 10.0
    beams: int = 360
    range_min: float = 0.15
    range_max: float = 12.0
    noise: float = 0.01
    topic: str = "scan"
    # first beam's angle and the last one's; None for the last: a full turn less one increment
    angle_min: float = -math.pi
    angle_max: float | None = None
    range_resolution: float = 0.0  # ranges rounded to this step (Gazebo's <range><resolution>); 0: none
    # Gazebo's laser plugins (gazebo_ros_laser, gpu_laser) publish scan_time 0 and one intensity per
    # ray (the ray sensor's retro value: 0 on surfaces without one); a spinning lidar's driver gives
    # the revolution's period and no intensities. True: the plugin's fields.
    gazebo_fields: bool = False


@dataclass
class CameraSpec:
    pose: SensorPose
    rate: float = 30.0
    width: int = 320
    height: int = 240
    hfov: float = 69.0
    depth_max: float = 10.0
    image_topic: str = "camera/color/image_raw"
    info_topic: str = "camera/color/camera_info"
    frame: str = "camera_color_optical_frame"
    # the depth stream (None: a colour-only camera, as Gazebo's plain camera plugin)
    depth_topic: str | None = "camera/depth/image_rect_raw"
    depth_info_topic: str | None = "camera/depth/camera_info"
    depth_frame: str = "camera_depth_optical_frame"
    #: gazebo_ros_camera's <hackBaseline> (m): CameraInfo's P[3] = -fx * baseline (a stereo pair's right camera)
    hack_baseline: float = 0.0


@dataclass
class ImuSpec:
    pose: SensorPose
    rate: float = 100.0
    gyro_noise: float = 0.001
    accel_noise: float = 0.01
    topic: str = "imu"


@dataclass
class GroundTruthSpec:
    """The true pose as nav_msgs/Odometry: our PuzzleBot's ``base_pose_ground_truth`` (Stage's name),
    or what a description's ``libgazebo_ros_p3d.so`` asks for (topicName, frameName, bodyName,
    updateRate; 0: every physics step, as the plugin does)."""

    topic: str = "base_pose_ground_truth"
    frame: str = "map"  # header.frame_id (p3d's frameName, "world" by default there)
    body: str = "base_link"  # child_frame_id (p3d's bodyName)
    rate: float | None = None  # Hz; None: the odometry's rate; 0: every physics step


@dataclass
class BumperSpec:
    """A description's ``<sensor type="contact">`` with ``libgazebo_ros_bumper.so``: what it publishes
    (gazebo_msgs/ContactsState on bumperTopicName, stamped in frameName) and for which collision."""

    topic: str = "bumper_states"
    frame: str = "world"
    collision: str = ""  # the sensor's <contact><collision>, as Gazebo scopes it: model::link::collision
    rate: float = 0.0  # Hz; 0: every physics step


@dataclass
class DriveSpec:
    """How the robot is driven and what its drive publishes: our PuzzleBot's defaults, or what a
    description's drive plugin (gazebo_ros_diff_drive, ros_control's DiffDriveController...) says."""

    kind: str = "puzzlebot"  # "puzzlebot", "diff_drive", "skid_steer", "ros_control" or "none" (passive)
    command_topic: str = "cmd_vel"
    odom_topic: str = "odom"
    odom_frame: str = "odom"
    base_frame: str = "base_link"
    publish_odom: bool = True
    publish_odom_tf: bool = True
    publish_wheel_tf: bool = False
    publish_wheel_joint_state: bool = True
    publish_wheel_speeds: bool = True  # the PuzzleBot's wl/wr encoder topics
    odometry_source: str = "encoder"  # or "world" (ground truth), as gazebo_ros_diff_drive's odometrySource
    update_rate: float | None = None  # None: RobotModel.odom_rate
    # the drive's own kinematics (gazebo_ros_diff_drive's wheelSeparation and wheelDiameter/2): the
    # wheel speeds for a cmd_vel are computed with these, the motion follows the URDF's wheels, so a
    # plugin value that differs from the geometry turns the robot at the rate Gazebo would. None: the model's.
    wheel_separation: float | None = None
    wheel_radius: float | None = None
    joint_states_topic: str = "joint_states"  # publishWheelJointState's topic
    # ros_control: the namespace of gazebo_ros_control's controller_manager and the description parameter
    controller_namespace: str = "/"
    robot_param: str = "robot_description"

    @classmethod
    def silent(cls, kind: str, **fields: object) -> DriveSpec:
        """A drive that subscribes and publishes nothing itself (ros_control's, or none at all)."""
        quiet: dict[str, object] = {
            "command_topic": "",
            "odom_topic": "",
            "publish_odom": False,
            "publish_odom_tf": False,
            "publish_wheel_joint_state": False,
            "publish_wheel_speeds": False,
        }
        return cls(kind=kind, **{**quiet, **fields})  # type: ignore[arg-type]


@dataclass
class RobotModel:
    name: str
    wheel_radius: float
    wheel_separation: float
    body_radius: float
    body_height: float
    color: tuple[int, int, int]
    max_wheel_speed: float
    max_wheel_accel: float
    left_joint: str
    right_joint: str
    laser: LaserSpec | None
    camera: CameraSpec | None
    imu: ImuSpec | None
    odom_rate: float = 100.0
    odom_alpha: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    source: str = field(default="")
    drive: DriveSpec = field(default_factory=DriveSpec)
    ignored_plugins: list[str] = field(default_factory=list)  # named once in a warning at spawn
    warnings: list[str] = field(default_factory=list)  # what the description lacks, logged once at spawn
    # False for a Gazebo description: robot_state_publisher publishes the link frames, the simulator does not
    sensor_tf: bool = True
    # ros_control: the joints with a <transmission> and their side ("left", "right"; "" for a joint that
    # is not a wheel): every wheel of a side turns as that side's wheel of the simulated body
    control_joints: dict[str, str] = field(default_factory=dict)
    #: gazebo_ros_control beside a plugin drive: its controller_manager (namespace, period) over
    #: ``control_joints``; the plugin keeps driving unless a running controller commands the wheels
    control_beside: DriveSpec | None = None
    #: the URDF's <limit velocity> of the joints ros_control exposes, where one is given (rad/s)
    joint_velocity_limits: dict[str, float] = field(default_factory=dict)
    #: what apply_body_wrench pushes: the body's mass (kg) and moment of inertia about the vertical
    #: (kg m^2), from a URDF's <inertial>s; None: a torque turns it as it would a 1 kg m^2 body
    mass: float = 1.0
    inertia_z: float | None = None
    #: gazebo_ros_diff_drive's publishWheelTF: the wheel joints whose parent -> child transforms go
    #: on /tf with the wheels' angles (left, right); empty when not asked for
    wheel_tf_joints: list[Joint] = field(default_factory=list)
    #: a description's further lidars and cameras (``laser`` and ``camera`` are its first ones), each
    #: on its plugin's own topics and frames, at its own rate
    extra_lasers: list[LaserSpec] = field(default_factory=list)
    extra_cameras: list[CameraSpec] = field(default_factory=list)
    #: the height of the model's frame (the description's root link) above the floor when the robot
    #: stands on it: Gazebo's model pose z once the robot has fallen or been pushed onto the floor
    #: (a root link at the wheels' axles stands at the wheel radius), whatever z it was spawned at
    rest_z: float = 0.0
    #: what the simulator publishes beyond the drive and sensors: our PuzzleBot's ground truth and
    #: ``contact`` (std_msgs/Bool); a Gazebo description gets only what its plugins ask for (p3d,
    #: bumper), as Gazebo publishes nothing else
    ground_truth: GroundTruthSpec | None = field(default_factory=GroundTruthSpec)
    contact_topic: str | None = "contact"
    bumper: BumperSpec | None = None


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


def _default_doc() -> dict:
    return yaml.safe_load((ROBOTS_DIR / "puzzlebot.yaml").read_text(encoding="utf-8"))


def _pose(f: Fields, d: dict, where: str) -> SensorPose:
    xyz = f.vector(d.get("xyz", [0, 0, 0]), f"{where}.xyz", 3)
    rpy = f.vector(d.get("rpy", [0, 0, 0]), f"{where}.rpy", 3)
    frame = d.get("frame")
    if not isinstance(frame, str) or not frame:
        raise f.error(f"{where}.frame", f"expected a frame name, got {frame!r}")
    return SensorPose(frame, (xyz[0], xyz[1], xyz[2]), (rpy[0], rpy[1], rpy[2]))


def model_from_doc(doc: dict, f: Fields) -> RobotModel:
    """Build a model from a (merged) description mapping; errors name file, line and field."""
    pos = {
        k: f.number(doc.get(k), k, positive=True)
        for k in (
            "wheel_radius",
            "wheel_separation",
            "body_radius",
            "body_height",
            "max_wheel_speed",
            "max_wheel_accel",
        )
    }
    colour = doc.get("color", [45, 45, 55])
    rgb = f.vector(colour, "color", 3)
    joints = doc.get("joints") or {}
    sensors = doc.get("sensors") or {}
    if not isinstance(sensors, dict):
        raise f.error("sensors", f"expected a mapping of laser/camera/imu, got {sensors!r}")
    for key in sensors:
        if key not in ("laser", "camera", "imu"):
            raise f.error(f"sensors.{key}", "unknown sensor (expected laser, camera or imu)")
    laser = camera = imu = None
    if isinstance(sensors.get("laser"), dict):
        s = sensors["laser"]
        laser = LaserSpec(
            _pose(f, s, "sensors.laser"),
            f.number(s.get("rate", 10.0), "sensors.laser.rate", positive=True),
            int(f.number(s.get("beams", 360), "sensors.laser.beams", positive=True)),
            f.number(s.get("range_min", 0.15), "sensors.laser.range_min", minimum=0),
            f.number(s.get("range_max", 12.0), "sensors.laser.range_max", positive=True),
            f.number(s.get("noise", 0.01), "sensors.laser.noise", minimum=0),
        )
        if laser.range_min >= laser.range_max:
            raise f.error("sensors.laser.range_min", "must be below range_max")
    if isinstance(sensors.get("camera"), dict):
        s = sensors["camera"]
        camera = CameraSpec(
            _pose(f, s, "sensors.camera"),
            f.number(s.get("rate", 30.0), "sensors.camera.rate", positive=True),
            int(f.number(s.get("width", 320), "sensors.camera.width", positive=True)),
            int(f.number(s.get("height", 240), "sensors.camera.height", positive=True)),
            f.number(s.get("hfov", 69.0), "sensors.camera.hfov", positive=True),
            f.number(s.get("depth_max", 10.0), "sensors.camera.depth_max", positive=True),
        )
        if camera.hfov >= 170:
            raise f.error("sensors.camera.hfov", "a pinhole camera needs hfov < 170 degrees")
    if isinstance(sensors.get("imu"), dict):
        s = sensors["imu"]
        imu = ImuSpec(
            _pose(f, s, "sensors.imu"),
            f.number(s.get("rate", 100.0), "sensors.imu.rate", positive=True),
            f.number(s.get("gyro_noise", 0.001), "sensors.imu.gyro_noise", minimum=0),
            f.number(s.get("accel_noise", 0.01), "sensors.imu.accel_noise", minimum=0),
        )
    odom = doc.get("odometry") or {}
    alpha = f.vector(odom.get("alpha", [0, 0, 0, 0]), "odometry.alpha", 4)
    if any(a < 0 for a in alpha):
        raise f.error("odometry.alpha", "noise parameters must be >= 0")
    return RobotModel(
        str(doc.get("name", "robot")),
        pos["wheel_radius"],
        pos["wheel_separation"],
        pos["body_radius"],
        pos["body_height"],
        (int(rgb[0]), int(rgb[1]), int(rgb[2])),
        pos["max_wheel_speed"],
        pos["max_wheel_accel"],
        str(joints.get("left", "wheel_left_joint")),
        str(joints.get("right", "wheel_right_joint")),
        laser,
        camera,
        imu,
        f.number(odom.get("rate", 100.0), "odometry.rate", positive=True),
        (alpha[0], alpha[1], alpha[2], alpha[3]),
        f.path,
    )


def load_robot_model(
    spec: str = "puzzlebot", *, robot_namespace: str | None = None, gazebo: bool | None = None
) -> RobotModel:
    """``puzzlebot`` (or another shipped name), a YAML description path, or a URDF/xacro path or text.

    ``gazebo`` picks the rules a URDF is read by: Gazebo's (``<gazebo>`` plugins say what drives and
    publishes; none: passive) or ours (the PuzzleBot's topics, with the URDF's geometry). ``None``
    decides by the presence of ``<gazebo>`` blocks; spawn_model passes True.
    """
    text_is_urdf = spec.lstrip().startswith("<")
    if text_is_urdf:
        return model_from_urdf(spec, "<robot_description>", robot_namespace=robot_namespace, gazebo=gazebo)
    path = Path(spec).expanduser()
    if path.suffix == ".xacro":
        from ninjemys.sim.description.build import expand_xacro

        text = expand_xacro(str(path))
        return model_from_urdf(text, str(path), robot_namespace=robot_namespace, gazebo=gazebo)
    if "/" not in spec and not spec.endswith((".yaml", ".yml", ".urdf")):
        path = ROBOTS_DIR / f"{spec}.yaml"
        if not path.is_file():
            known = ", ".join(sorted(p.stem for p in ROBOTS_DIR.glob("*.yaml")))
            raise MapFileError(
                f"model '{spec}': no such shipped robot (shipped: {known}; or give a YAML/URDF path)"
            )
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise MapFileError(f"{path}: cannot read robot description: {exc.strerror or exc}") from None
    if path.suffix == ".urdf" or text.lstrip().startswith("<"):
        return model_from_urdf(text, str(path), robot_namespace=robot_namespace, gazebo=gazebo)
    doc, lines = yaml_lines(text, str(path))
    f = Fields(str(path), lines)
    if not isinstance(doc, dict):
        raise f.error("", "a robot description is a YAML mapping (see robots/puzzlebot.yaml)")
    return model_from_doc(_merge(_default_doc(), doc), f)


def _floats(text: str | None, n: int, where: str, source: str) -> list[float]:
    try:
        values = [float(v) for v in (text or " ".join(["0"] * n)).split()]
    except ValueError:
        raise MapFileError(f"{source}: {where}: expected {n} numbers, got {text!r}") from None
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise MapFileError(f"{source}: {where}: expected {n} finite numbers, got {text!r}")
    return values


def model_from_urdf(
    text: str, source: str, *, robot_namespace: str | None = None, gazebo: bool | None = None
) -> RobotModel:
    """A URDF under Gazebo's rules (see :mod:`ninjemys.sim.description`) or, without ``<gazebo>``
    blocks, our subset: base link cylinder, continuous wheel joints, fixed sensor joints."""
    from ninjemys.sim.description.build import has_gazebo_blocks, model_from_description

    if gazebo or (gazebo is None and has_gazebo_blocks(text)):
        return model_from_description(text, source, robot_namespace=robot_namespace)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line = exc.position[0] if exc.position else 0
        raise MapFileError(f"{source}:{line}: invalid URDF XML: {exc}") from None
    if root.tag != "robot":
        raise MapFileError(f"{source}: URDF root element is <{root.tag}>, expected <robot>")
    try:
        parse_urdf(text, source)  # what urdfdom refuses (a joint naming a missing link), Gazebo does not load
    except URDFError as exc:
        raise MapFileError(str(exc)) from None
    doc = _default_doc()
    doc["name"] = root.get("name", "robot")
    links = {link.get("name"): link for link in root.findall("link")}
    joints = root.findall("joint")

    def cylinder(link_name: str | None) -> tuple[float, float] | None:
        link = links.get(link_name)
        cyl = link.find("collision/geometry/cylinder") if link is not None else None
        if cyl is None and link is not None:
            cyl = link.find("visual/geometry/cylinder")
        if cyl is None:
            return None
        radius = _floats(cyl.get("radius"), 1, f"link {link_name} cylinder radius", source)[0]
        length = _floats(cyl.get("length"), 1, f"link {link_name} cylinder length", source)[0]
        return radius, length

    wheels = [j for j in joints if j.get("type") == "continuous"]
    if len(wheels) != 2:
        raise MapFileError(
            f"{source}: a differential-drive URDF needs exactly 2 continuous wheel joints, found {len(wheels)}"
        )
    ys = []
    for j in wheels:
        origin = j.find("origin")
        xyz = _floats(
            origin.get("xyz") if origin is not None else None, 3, f"joint {j.get('name')} origin xyz", source
        )
        ys.append(xyz[1])
        child = j.find("child")
        wheel = cylinder(child.get("link") if child is not None else None)
        if wheel is not None:
            doc["wheel_radius"] = wheel[0]
    left, right = (wheels[0], wheels[1]) if ys[0] > ys[1] else (wheels[1], wheels[0])
    doc["wheel_separation"] = abs(ys[0] - ys[1])
    doc["joints"] = {"left": left.get("name"), "right": right.get("name")}
    children = {c.get("link") for c in (j.find("child") for j in joints) if c is not None}
    root_link = next((n for n in links if n not in children), None)
    body = cylinder(root_link)
    if body is not None:
        doc["body_radius"], doc["body_height"] = body
    sensors: dict = {}
    for j in joints:
        child_element = j.find("child")
        if j.get("type") != "fixed" or child_element is None:
            continue
        child_link = child_element.get("link") or ""
        kind = {"laser": "laser", "camera_link": "camera", "imu_link": "imu"}.get(child_link)
        if kind is None:
            continue
        origin = j.find("origin")
        xyz = _floats(
            origin.get("xyz") if origin is not None else None, 3, f"joint {j.get('name')} origin xyz", source
        )
        rpy = _floats(
            origin.get("rpy") if origin is not None else None, 3, f"joint {j.get('name')} origin rpy", source
        )
        sensors[kind] = dict(doc["sensors"][kind], frame=child_link, xyz=xyz, rpy=rpy)
    doc["sensors"] = sensors
    return model_from_doc(doc, Fields(source, {}))
