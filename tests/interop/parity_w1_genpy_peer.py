"""genpy as ROS 1 programs use it, printed as JSON (run under either interpreter): isinstance and
Time/Duration identities, fill_message_args on good and bad arguments, check_type's verdicts and
texts, strify_message, and the (de)serialization errors messages raise."""

import io
import json

import genpy
import genpy.message as gm
import rospy
from geometry_msgs.msg import Point, PoseArray, PoseStamped, Vector3
from sensor_msgs.msg import JointState
from std_msgs.msg import Header, String, UInt8MultiArray


def attempt(f, *args):
    try:
        r = f(*args)
        return ["ok", str(r) if r is not None else None]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


def filled(cls, args, keys=None):
    m = cls()
    try:
        gm.fill_message_args(m, args, keys or {})
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]
    return ["ok", gm.strify_message(m)]


out = {"types": {}, "fill": {}, "check": {}, "strify": {}, "errors": {}}
out["types"]["isinstance"] = [isinstance(String(), genpy.Message), isinstance(Point(), gm.Message)]
out["types"]["time"] = [
    isinstance(rospy.Time(1, 2), genpy.Time),
    genpy.Time(1, 2) == rospy.Time(1, 2),
    str(genpy.Time(3, 500000000) - genpy.Time(1, 0)),
    type(genpy.Time(3) - genpy.Time(1)).__name__,
    genpy.Duration(1, 500000000).to_sec(),
    isinstance(genpy.Duration(1), genpy.TVal),
    genpy.Time.from_sec(1.25).to_nsec(),
]
out["types"]["errors"] = [
    issubclass(genpy.SerializationError, Exception),
    issubclass(genpy.DeserializationError, Exception),
    issubclass(genpy.MessageException, Exception),
]
out["types"]["struct_I"] = genpy.struct_I.pack(7).hex()

now = genpy.Time(5, 6)
out["fill"]["list"] = filled(Point, [1, 2.5, 3])
out["fill"]["dict"] = filled(Point, [{"x": 1, "z": 2}])
out["fill"]["nested_dict"] = filled(
    PoseStamped, [{"header": {"frame_id": "map", "seq": 3}, "pose": {"position": {"x": 1}}}]
)
out["fill"]["nested_list"] = filled(Vector3, [[1, 2, 3]])
out["fill"]["stamp_now"] = filled(PoseStamped, [{"header": {"stamp": "now"}}], {"now": now})
out["fill"]["stamp_int"] = filled(Header, [{"stamp": 1500000000}])
out["fill"]["header_key"] = filled(PoseStamped, [{"header": "auto"}], {"auto": Header(frame_id="k")})
out["fill"]["array_of_msgs"] = filled(
    PoseArray, [{"poses": [{"position": {"x": 1}}, {"orientation": {"w": 1}}]}]
)
out["fill"]["primitive_array"] = filled(JointState, [{"name": ["a", "b"], "position": [1.0, 2.0]}])
out["fill"]["too_many"] = filled(Point, [1, 2, 3, 4])
out["fill"]["not_enough"] = filled(Point, [1])
out["fill"]["no_field"] = filled(Point, [{"w": 1}])
out["fill"]["no_key"] = filled(PoseStamped, [{"header": {"stamp": "later"}}])
out["fill"]["not_list"] = filled(JointState, [{"name": 5}])
out["fill"]["none_args"] = filled(String, None)
out["fill"]["bad_msg"] = attempt(gm.fill_message_args, 5, [1])
out["fill"]["bad_args"] = attempt(gm._fill_message_args, Point(), 7, {})
out["fill"]["string_none"] = filled(String, [{"data": None}])

CHECKS = [
    ("int8", 5),
    ("int8", 200),
    ("int8", 1.5),
    ("uint8", -1),
    ("uint8", 255),
    ("uint8", 256),
    ("uint64", 2**64),
    ("int64", -(2**63)),
    ("float32", 1),
    ("float64", "x"),
    ("bool", 2),
    ("bool", True),
    ("string", "abc"),
    ("string", "é"),
    ("string", b"x"),
    ("string", 5),
    ("time", genpy.Time(1)),
    ("time", genpy.Duration(1)),
    ("duration", 1),
    ("uint8[]", b"ab"),
    ("int32[]", "ab"),
    ("int32[]", 5),
    ("int32[]", [1, 2**40]),
    ("float64[3]", (1.0, 2.0, 3.0)),
    ("geometry_msgs/Point", Point()),
    ("geometry_msgs/Point", Vector3()),
    ("Header", Header()),
    ("geometry_msgs/Point", Header()),
    ("geometry_msgs/Point", 5),
    ("geometry_msgs/Point", Point(x="bad")),
]
for t, v in CHECKS:
    shown = v.to_nsec() if isinstance(v, genpy.TVal) else v  # our Time prints as rospy.Time (one class)
    out["check"][f"{t}={type(v).__name__}:{shown!r}"] = attempt(gm.check_type, "f", t, v)

ps = PoseStamped()
ps.header.frame_id = "map"
ps.header.stamp = genpy.Time(10, 5)
ps.pose.position.x = 1.5
js = JointState(name=["a", "b"], position=[1.0, 2.5])
out["strify"]["pose"] = gm.strify_message(ps)
out["strify"]["pose_indent"] = gm.strify_message(ps, indent="  ")
out["strify"]["joint"] = gm.strify_message(js)
out["strify"]["offset"] = gm.strify_message(ps, time_offset=genpy.Time(4, 0))
out["strify"]["bytes"] = gm.strify_message(UInt8MultiArray(data=b"\x01\x02"))
out["strify"]["scalars"] = [gm.strify_message(v) for v in (1, 2.5, True, "", "text", [], [1, 2], ["a"])]
out["strify"]["width"] = gm.strify_message(Point(x=1.5, y=2, z=3), fixed_numeric_width=6)
out["strify"]["filter"] = gm.strify_message(Point(x=1, y=2, z=3), field_filter=lambda m: ["x", "z"])
out["strify"]["printable"] = gm.get_printable_message_args(ps)

buf = io.BytesIO()
try:
    String(data=5).serialize(buf)
except genpy.SerializationError as exc:
    out["errors"]["serialize"] = type(exc).__name__
try:
    String().deserialize(b"\x09\x00\x00\x00ab")
except genpy.DeserializationError as exc:
    out["errors"]["deserialize"] = type(exc).__name__
import genpy.dynamic  # noqa: E402

SEP = "=" * 80
CAT = (
    "Header header\nw1/Inner[] inners\ngeometry_msgs/Point where\nint32 K=3\n"
    f"{SEP}\nMSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
    f"{SEP}\nMSG: w1/Inner\nstring label\nfloat64[2] pair\n"
    f"{SEP}\nMSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"
)
out["dynamic"] = {}
classes = genpy.dynamic.generate_dynamic("w1/Thing", CAT)
out["dynamic"]["types"] = sorted(classes)
out["dynamic"]["md5"] = {t: c._md5sum for t, c in sorted(classes.items())}
thing = classes["w1/Thing"]()
thing.header.frame_id = "f"
inner = classes["w1/Inner"](label="a", pair=[1.0, 2.0])
thing.inners = [inner]
thing.where.x = 4.0
buf = io.BytesIO()
thing.serialize(buf)
out["dynamic"]["wire"] = buf.getvalue().hex()
out["dynamic"]["back"] = str(classes["w1/Thing"]().deserialize(buf.getvalue()))
out["dynamic"]["const"] = classes["w1/Thing"].K
out["dynamic"]["slots"] = list(classes["w1/Thing"].__slots__)
try:
    genpy.dynamic.generate_dynamic("w1/Bad", "int32 x\n" + SEP + "\nnot a msg line\n")
except Exception as exc:  # noqa: BLE001
    out["dynamic"]["bad"] = type(exc).__name__
print(json.dumps(out, sort_keys=True))
