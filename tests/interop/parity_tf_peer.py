"""The tf and tf2_ros calls programs make most, on one fixed tree, printed as JSON (run under either
interpreter, no master needed): tf's Transformer/TransformerROS (lookups, transformPoint/Pose/
Quaternion/Vector3 at Time(0), asMatrix, getLatestCommonTime ...), tf2_ros.Buffer (lookup_transform,
can_transform with its debug text, transform() with new_type) and the exception each mistake raises,
with its text. tests/interop/test_parity_behaviour.py compares ours with Debian's."""

import json
import math
import re

import numpy

import rospy
import tf
import tf2_geometry_msgs  # noqa: F401 - registers the stamped types with Buffer.transform
import tf2_ros
from geometry_msgs.msg import (
    Point,
    Point32,
    PointStamped,
    Pose,
    PoseStamped,
    Quaternion,
    QuaternionStamped,
    TransformStamped,
    Vector3,
    Vector3Stamped,
    Wrench,
    WrenchStamped,
)
from sensor_msgs.msg import ChannelFloat32, PointCloud
from std_msgs.msg import Header


def rounded(x):
    if isinstance(x, dict):
        return {k: rounded(v) for k, v in x.items()}
    if isinstance(x, float):
        return round(x, 9) + 0.0
    if isinstance(x, (list, tuple)):
        return [rounded(v) for v in x]
    if isinstance(x, numpy.ndarray):
        return rounded(x.tolist())
    return x


def printed(msg):
    """``str(msg)`` (the YAML form programs print) with its floats to 9 decimals."""
    return re.sub(r"-?\d+\.\d+(e-?\d+)?", lambda m: "%.9f" % (float(m.group()) + 0.0), str(msg))


def outcome(fn, *args, **kwargs):
    try:
        return ["ok", fn(*args, **kwargs)]
    except Exception as exc:
        bases = [c.__name__ for c in type(exc).__mro__ if c.__name__ not in ("NinjemysError", "object")]
        return ["raise", bases, str(exc)]


def stamped(parent, child, secs, xyz, rpy):
    t = TransformStamped()
    t.header.frame_id = parent
    t.header.stamp = rospy.Time.from_sec(secs)
    t.child_frame_id = child
    t.transform.translation = Vector3(*xyz)
    t.transform.rotation = Quaternion(*tf.transformations.quaternion_from_euler(*rpy))
    return t


TREE = [
    ("map", "odom", (1.0, 2.0, 0.0), (0.0, 0.0, 0.3)),
    ("odom", "base_link", (0.5, -0.25, 0.0), (0.0, 0.0, -0.7)),
    ("base_link", "laser", (0.2, 0.0, 0.15), (0.0, 0.1, math.pi)),
    ("island", "lonely", (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
]


def fill(set_transform):
    for secs in (10.0, 11.0, 12.0):
        for parent, child, xyz, rpy in TREE:
            moved = tuple(v + 0.1 * (secs - 10.0) for v in xyz)
            turned = (rpy[0], rpy[1], rpy[2] + 0.05 * (secs - 10.0))
            set_transform(stamped(parent, child, secs, moved, turned))


def pose_out(ps):
    p, o = ps.pose.position, ps.pose.orientation
    return [ps.header.frame_id, ps.header.stamp.to_sec(), rounded([p.x, p.y, p.z, o.x, o.y, o.z, o.w])]


def tf_checks():
    out = {}
    t = tf.TransformerROS(True, rospy.Duration(10.0))
    fill(lambda m: t.setTransform(m, "peer"))
    zero, mid, late = rospy.Time(0), rospy.Time.from_sec(11.5), rospy.Time.from_sec(30.0)
    early = rospy.Time.from_sec(1.0)
    out["lookup_latest"] = outcome(lambda: rounded(t.lookupTransform("map", "laser", zero)))
    out["lookup_mid"] = outcome(lambda: rounded(t.lookupTransform("laser", "map", mid)))
    out["lookup_slash"] = outcome(lambda: rounded(t.lookupTransform("/map", "/base_link", mid)))
    out["lookup_future"] = outcome(t.lookupTransform, "map", "laser", late)
    out["lookup_past"] = outcome(t.lookupTransform, "map", "laser", early)
    out["lookup_unknown"] = outcome(t.lookupTransform, "map", "nowhere", zero)
    out["lookup_disconnected"] = outcome(t.lookupTransform, "map", "lonely", zero)
    out["lookup_full"] = outcome(
        lambda: rounded(t.lookupTransformFull("laser", mid, "base_link", rospy.Time.from_sec(10.5), "map"))
    )
    out["can"] = [t.canTransform("map", "laser", zero), t.canTransform("map", "lonely", zero)]
    out["common_time"] = outcome(lambda: t.getLatestCommonTime("map", "laser").to_sec())
    out["common_time_unknown"] = outcome(t.getLatestCommonTime, "map", "nowhere")
    out["exists"] = [t.frameExists("laser"), t.frameExists("map"), t.frameExists("nowhere")]
    out["frames"] = sorted(t.getFrameStrings())
    out["matrix"] = outcome(lambda: rounded(t.asMatrix("map", Header(frame_id="laser", stamp=mid))))
    out["from_tr"] = rounded(t.fromTranslationRotation((1, 2, 3), (0, 0, math.sin(0.2), math.cos(0.2))))
    for when, stamp in (("zero", zero), ("mid", mid)):
        ps = PointStamped(Header(frame_id="laser", stamp=stamp), Point(1.0, 2.0, 3.0))
        out[f"point_{when}"] = outcome(
            lambda ps=ps: [
                (r := t.transformPoint("map", ps)).header.frame_id,
                r.header.stamp.to_sec(),
                rounded([r.point.x, r.point.y, r.point.z]),
            ]
        )
        pose = PoseStamped(
            Header(frame_id="laser", stamp=stamp), Pose(Point(1, 0, 0), Quaternion(0, 0, 0, 1))
        )
        out[f"pose_{when}"] = outcome(lambda pose=pose: pose_out(t.transformPose("odom", pose)))
        qs = QuaternionStamped(Header(frame_id="base_link", stamp=stamp), Quaternion(0, 0, 0, 1))
        out[f"quat_{when}"] = outcome(
            lambda qs=qs: rounded([(q := t.transformQuaternion("map", qs).quaternion).x, q.y, q.z, q.w])
        )
        vs = Vector3Stamped(Header(frame_id="laser", stamp=stamp), Vector3(1.0, 0.0, 0.0))
        out[f"vector_{when}"] = outcome(
            lambda vs=vs: rounded([(v := t.transformVector3("map", vs).vector).x, v.y, v.z])
        )
    bad = PointStamped(Header(frame_id="nowhere", stamp=zero), Point(1.0, 2.0, 3.0))
    out["point_unknown"] = outcome(t.transformPoint, "map", bad)
    out["kinds"] = [
        kind(t.lookupTransform("map", "laser", zero)),
        kind(t.lookupTransformFull("laser", mid, "base_link", mid, "map")),
        kind(t.lookupTwist("base_link", "map", rospy.Time.from_sec(11.0), rospy.Duration(1.0))),
        type(t.getLatestCommonTime("map", "laser")).__name__,
        kind(t.getFrameStrings()),
        kind(t.asMatrix("map", Header(frame_id="laser", stamp=mid))),
    ]
    odd = tf.Transformer(True, rospy.Duration(10.0))
    slash = stamped("/world", "/thing", 5.0, (1, 0, 0), (0, 0, 0))
    empty = stamped("world", "", 5.0, (1, 0, 0), (0, 0, 0))
    nan = stamped("world", "nan_frame", 5.0, (float("nan"), 0, 0), (0, 0, 0))
    for m in (slash, empty, nan):
        out[f"odd_set_{m.child_frame_id or 'empty'}"] = outcome(odd.setTransform, m, "peer")
    out["odd_frames"] = sorted(odd.getFrameStrings())
    out["odd_lookup"] = outcome(lambda: rounded(odd.lookupTransform("world", "thing", zero)))
    out["odd_lookup_slash"] = outcome(lambda: rounded(odd.lookupTransform("/world", "/thing", zero)))
    cloud = PointCloud(
        Header(frame_id="laser", stamp=mid),
        [Point32(1, 2, 3), Point32(-1, 0, 0.5)],
        [ChannelFloat32("intensity", [0.5, 0.25])],
    )
    moved = t.transformPointCloud("map", cloud)
    out["point_cloud"] = [
        moved.header.frame_id,
        rounded([[p.x, p.y, p.z] for p in moved.points]),
        [(c.name, c.values) for c in moved.channels],
    ]
    out["can_full"] = [
        t.canTransformFull("laser", mid, "base_link", mid, "map"),
        t.canTransformFull("laser", mid, "lonely", mid, "map"),
    ]
    out["prefix"] = t.getTFPrefix()
    out["frames_string"] = sorted(t.allFramesAsString().splitlines())
    out["chain"] = outcome(t.chain, "laser", mid, "lonely", mid, "map")
    out["chain_ok"] = outcome(lambda: sorted(t.chain("laser", mid, "odom", mid, "map")))
    out["dot"] = outcome(lambda: sorted(t.allFramesAsDot().splitlines()))
    out["wait_no_thread"] = outcome(t.waitForTransform, "map", "laser", zero, rospy.Duration(0.01))
    out["twist"] = outcome(
        lambda: rounded(
            list(t.lookupTwist("base_link", "map", rospy.Time.from_sec(11.0), rospy.Duration(1.0)))
        )
    )
    return out


def tf2_checks():
    out = {}
    b = tf2_ros.Buffer(rospy.Duration(10.0), debug=False)
    fill(lambda m: b.set_transform(m, "peer"))
    zero, mid = rospy.Time(0), rospy.Time.from_sec(11.5)

    def tr(m):
        r, q = m.transform.translation, m.transform.rotation
        return [
            m.header.frame_id,
            m.child_frame_id,
            m.header.stamp.to_sec(),
            rounded([r.x, r.y, r.z, q.x, q.y, q.z, q.w]),
        ]

    out["lookup_zero"] = outcome(lambda: tr(b.lookup_transform("map", "laser", zero)))
    out["lookup_mid"] = outcome(lambda: tr(b.lookup_transform("laser", "odom", mid)))
    out["lookup_full"] = outcome(
        lambda: tr(b.lookup_transform_full("laser", mid, "base_link", rospy.Time.from_sec(10.5), "map"))
    )
    out["lookup_future"] = outcome(b.lookup_transform, "map", "laser", rospy.Time.from_sec(13.5))
    out["lookup_past"] = outcome(b.lookup_transform, "map", "laser", rospy.Time.from_sec(2.0))
    out["lookup_unknown"] = outcome(b.lookup_transform, "map", "nowhere", zero)
    out["lookup_unknown_both"] = outcome(b.lookup_transform, "nowhere", "elsewhere", zero)
    out["lookup_disconnected"] = outcome(b.lookup_transform, "map", "lonely", zero)
    out["lookup_slash"] = outcome(b.lookup_transform, "/map", "laser", zero)
    out["lookup_empty"] = outcome(b.lookup_transform, "", "laser", zero)
    out["can"] = [
        b.can_transform("map", "laser", zero),
        b.can_transform("map", "lonely", zero),
        b.can_transform("map", "laser", rospy.Time.from_sec(20.0)),
    ]
    out["can_debug"] = [
        list(b.can_transform("map", "nowhere", zero, return_debug_tuple=True)),
        list(b.can_transform("map", "lonely", zero, return_debug_tuple=True)),
        list(b.can_transform("map", "laser", rospy.Time.from_sec(20.0), return_debug_tuple=True)),
    ]
    for when, stamp in (("zero", zero), ("mid", mid)):
        ps = PointStamped(Header(frame_id="laser", stamp=stamp), Point(1.0, 2.0, 3.0))
        out[f"point_{when}"] = outcome(
            lambda ps=ps: [
                (r := b.transform(ps, "map")).header.frame_id,
                r.header.stamp.to_sec(),
                rounded([r.point.x, r.point.y, r.point.z]),
            ]
        )
        out[f"point_typed_{when}"] = outcome(
            lambda ps=ps: type(b.transform(ps, "map", new_type=PointStamped)).__name__
        )
        pose = PoseStamped(
            Header(frame_id="laser", stamp=stamp), Pose(Point(1, 0, 0), Quaternion(0, 0, 0, 1))
        )
        out[f"pose_{when}"] = outcome(lambda pose=pose: pose_out(b.transform(pose, "odom")))
        vs = Vector3Stamped(Header(frame_id="laser", stamp=stamp), Vector3(1.0, 0.0, 0.0))
        out[f"vector_{when}"] = outcome(
            lambda vs=vs: [
                (r := b.transform(vs, "map")).header.frame_id,
                rounded([r.vector.x, r.vector.y, r.vector.z]),
            ]
        )
    out["transform_unregistered"] = outcome(b.transform, Header(frame_id="laser"), "map")
    out["transform_full"] = outcome(
        lambda: pose_out(
            b.transform_full(
                PoseStamped(
                    Header(frame_id="laser", stamp=mid), Pose(Point(1, 0, 0), Quaternion(0, 0, 0, 1))
                ),
                "base_link",
                rospy.Time.from_sec(10.5),
                "map",
            )
        )
    )
    out["new_type_unknown"] = outcome(
        b.transform, PointStamped(Header(frame_id="laser", stamp=zero), Point()), "map", new_type=Point
    )
    link = b.lookup_transform("map", "laser", mid)
    direct = {
        "point": PointStamped(Header(frame_id="laser", stamp=mid), Point(1.0, 2.0, 3.0)),
        "vector3": Vector3Stamped(Header(frame_id="laser", stamp=mid), Vector3(1.0, 2.0, 3.0)),
        "pose": PoseStamped(
            Header(frame_id="laser", stamp=mid), Pose(Point(1, 2, 3), Quaternion(0, 0.6, 0, 0.8))
        ),
    }
    for name, msg in direct.items():
        res = getattr(tf2_geometry_msgs, f"do_transform_{name}")(msg, link)
        out[f"do_{name}"] = [type(res).__name__, res.header.frame_id, printed(res)]
    wrench = WrenchStamped(Header(frame_id="laser", stamp=mid), Wrench(Vector3(1, 2, 3), Vector3(-1, 0, 2)))
    res = tf2_geometry_msgs.do_transform_wrench(wrench, link)
    out["do_wrench"] = [type(res).__name__, res.header.frame_id, printed(res)]
    frames = __import__("yaml").safe_load(b.all_frames_as_yaml()) or {}
    out["yaml"] = {k: sorted(v) for k, v in frames.items()}
    out["yaml_values"] = {
        k: [
            v["parent"],
            v["broadcaster"],
            v["rate"],
            v["most_recent_transform"],
            v["oldest_transform"],
            v["buffer_length"],
        ]
        for k, v in frames.items()
    }
    out["string"] = sorted(b.all_frames_as_string().splitlines())
    bad = TransformStamped()
    bad.header.frame_id = "a"
    bad.child_frame_id = "a"
    bad.transform.rotation.w = 1.0
    out["self_parent"] = outcome(lambda: b.set_transform(bad, "peer"))
    nan = stamped("a", "b", 1.0, (0, 0, 0), (0, 0, 0))
    nan.transform.rotation = Quaternion(0, 0, 0, 0)
    out["zero_quaternion"] = outcome(lambda: b.set_transform(nan, "peer"))
    out["hierarchy"] = [
        [c.__name__ for c in cls.__mro__ if c.__name__ not in ("NinjemysError", "object")]
        for cls in (
            tf2_ros.LookupException,
            tf2_ros.ConnectivityException,
            tf2_ros.ExtrapolationException,
            tf2_ros.InvalidArgumentException,
            tf2_ros.TimeoutException,
            tf.Exception,
            tf.LookupException,
        )
    ]
    return out


def transformations_checks():
    tt = tf.transformations
    q = tt.quaternion_from_euler(0.1, -0.4, 2.0)
    m = tt.euler_matrix(0.3, 0.2, -0.1, "rzyx")
    out = {
        "q": q,
        "euler_axes": [tt.euler_from_quaternion(q, axes) for axes in sorted(tt._AXES2TUPLE)],
        "m": m,
        "from_matrix": [tt.euler_from_matrix(m), tt.euler_from_matrix(m, "szxy")],
        "quat_ops": [
            tt.quaternion_multiply(q, tt.quaternion_inverse(q)),
            tt.quaternion_conjugate(q),
            tt.quaternion_slerp(q, [0, 0, 0, 1], 0.3),
            tt.quaternion_about_axis(0.5, (1, 0, 0)),
            tt.quaternion_from_matrix(m),
            tt.quaternion_matrix(q),
        ],
        "compose": tt.compose_matrix(scale=(1, 2, 3), angles=(0.1, 0.2, 0.3), translate=(4, 5, 6)),
        "decompose": [
            list(x)
            for x in tt.decompose_matrix(tt.compose_matrix(angles=(0.1, 0.2, 0.3), translate=(4, 5, 6)))
        ],
        "rotation": [
            tt.rotation_matrix(0.4, (0, 0, 1), (1, 1, 0)),
            list(tt.rotation_from_matrix(tt.rotation_matrix(0.4, (0, 0, 1)))),
        ],
        "translation": [
            tt.translation_matrix((1, 2, 3)),
            tt.translation_from_matrix(m),
            tt.inverse_matrix(m),
        ],
        "identity": tt.identity_matrix(),
        "vector": [tt.unit_vector((1, 2, 2)), tt.vector_norm((3, 4, 0))],
        "concat": tt.concatenate_matrices(m, tt.translation_matrix((1, 0, 0))),
        "is_same": tt.is_same_transform(m, m),
        "random": [tt.random_quaternion((0.1, 0.5, 0.9)), tt.random_rotation_matrix((0.2, 0.4, 0.6))],
        "scale": [
            tt.scale_matrix(2.0, (1, 2, 3)),
            tt.scale_matrix(0.5, None, (1, 0, 0)),
            list(tt.scale_from_matrix(tt.scale_matrix(2.0, (1, 2, 3))))[:1],
        ],
        "reflection": [
            tt.reflection_matrix((1, 2, 3), (0, 0, 1)),
            [list(v) for v in tt.reflection_from_matrix(tt.reflection_matrix((1, 2, 3), (0, 0, 1)))],
        ],
        "projection": [
            tt.projection_matrix((0, 0, 0), (1, 0, 0)),
            tt.projection_matrix((0, 0, 0), (1, 0, 0), perspective=(5, 0, 0)),
            tt.projection_matrix((0, 0, 0), (1, 0, 0), direction=(1, 1, 0)),
        ],
        "clip": [tt.clip_matrix(-1, 1, -1, 1, 1, 10), tt.clip_matrix(-1, 1, -1, 1, 1, 10, perspective=True)],
        "shear": [
            tt.shear_matrix(0.3, (1, 0, 0), (0, 0, 0), (0, 0, 1)),
            [
                list(v) if hasattr(v, "__len__") else v
                for v in tt.shear_from_matrix(tt.shear_matrix(0.3, (1, 0, 0), (0, 0, 0), (0, 0, 1)))
            ][:1],
        ],
        "ortho": tt.orthogonalization_matrix((10, 10, 10), (90, 90, 90)),
        "superimposition": tt.superimposition_matrix(
            [[0, 1, 2, 3], [0, 0, 1, 1], [0, 0, 0, 1]],
            [[1, 1, 2, 4], [0, 1, 1, 2], [2, 2, 2, 3]],
            scaling=True,
        ),
        "arcball": [
            tt.arcball_map_to_sphere((320, 240), (320, 240), 200),
            tt.arcball_map_to_sphere((400, 100), (320, 240), 200),
            tt.arcball_constrain_to_axis((0.3, 0.4, 0.8), (1, 0, 0)),
            tt.arcball_nearest_axis((0.3, 0.4, 0.8), [(1, 0, 0), (0, 1, 0)]),
        ],
        "slerp_ends": [
            tt.quaternion_slerp(q, [0, 0, 0, 1], 0.0),
            tt.quaternion_slerp(q, [0, 0, 0, 1], 1.0),
            tt.quaternion_slerp(q, q, 0.5),
            tt.quaternion_slerp(q, -q, 0.5, spin=1),
        ],
        "euler_edge": [
            tt.euler_from_matrix(tt.euler_matrix(0, math.pi / 2, 0)),
            tt.quaternion_from_euler(0, 0, 0, "rxyz"),
        ],
    }
    ball = tt.Arcball()
    ball.place([320, 320], 320)
    ball.down([500, 250])
    ball.drag([475, 275])
    out["arcball_drag"] = ball.matrix()
    return rounded(json.loads(json.dumps(out, default=lambda o: rounded(o))))


def kind(v):
    """The shape of a return value: what programs print and index."""
    if isinstance(v, numpy.ndarray):
        return ["ndarray", str(v.dtype), list(v.shape)]
    if isinstance(v, (tuple, list)):
        return [type(v).__name__, [kind(x) for x in v]]
    return type(v).__name__


def return_types():
    tt = tf.transformations
    q = tt.quaternion_from_euler(0.1, -0.4, 2.0)
    m = tt.euler_matrix(0.3, 0.2, -0.1)
    calls = {
        "quaternion_from_euler": lambda: tt.quaternion_from_euler(0.1, 0.2, 0.3),
        "euler_from_quaternion": lambda: tt.euler_from_quaternion(q),
        "euler_from_quaternion_list": lambda: tt.euler_from_quaternion([0, 0, 0, 1]),
        "euler_from_matrix": lambda: tt.euler_from_matrix(m),
        "quaternion_multiply": lambda: tt.quaternion_multiply(q, q),
        "quaternion_inverse": lambda: tt.quaternion_inverse(q),
        "quaternion_conjugate": lambda: tt.quaternion_conjugate(q),
        "quaternion_matrix": lambda: tt.quaternion_matrix(q),
        "quaternion_from_matrix": lambda: tt.quaternion_from_matrix(m),
        "quaternion_slerp": lambda: tt.quaternion_slerp(q, [0, 0, 0, 1], 0.5),
        "quaternion_about_axis": lambda: tt.quaternion_about_axis(0.3, (0, 0, 1)),
        "translation_from_matrix": lambda: tt.translation_from_matrix(m),
        "translation_matrix": lambda: tt.translation_matrix((1, 2, 3)),
        "rotation_from_matrix": lambda: tt.rotation_from_matrix(tt.rotation_matrix(0.3, (0, 0, 1))),
        "decompose_matrix": lambda: tt.decompose_matrix(m),
        "unit_vector": lambda: tt.unit_vector([1, 2, 3]),
        "vector_norm": lambda: tt.vector_norm([1, 2, 3]),
        "random_quaternion": lambda: tt.random_quaternion(),
        "random_vector": lambda: tt.random_vector(3),
        "identity_matrix": lambda: tt.identity_matrix(),
        "is_same_transform": lambda: tt.is_same_transform(m, m),
        "inverse_matrix": lambda: tt.inverse_matrix(m),
        "concatenate_matrices": lambda: tt.concatenate_matrices(m, m),
        "from_translation_rotation": lambda: tf.TransformerROS().fromTranslationRotation(
            (1, 2, 3), (0, 0, 0, 1)
        ),
    }
    return {name: kind(call()) for name, call in calls.items()}


print(
    json.dumps(
        {
            "types": return_types(),
            "tf": tf_checks(),
            "tf2": tf2_checks(),
            "transformations": transformations_checks(),
        },
        default=str,
    )
)
