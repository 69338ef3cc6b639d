"""The rospy facade without a master: exceptions, implicit construction, AnyMsg, numpy_msg, pre-init state."""

from __future__ import annotations

import io
import time

import pytest

import rospy
from ninjemys import errors
from ninjemys.node.timers import TimeMovedBackwardsError
from rospy.exceptions import translate
from rospy.msg import AnyMsg, args_kwds_to_message
from std_msgs.msg import Header, Int32, String


def test_everyday_api_is_exported() -> None:
    for name in (
        "init_node get_name get_namespace get_caller_id resolve_name myargv Publisher Subscriber Service "
        "ServiceProxy ServiceException wait_for_service wait_for_message spin sleep Rate Timer TimerEvent Time "
        "Duration get_time get_rostime is_shutdown signal_shutdown on_shutdown ROSException "
        "ROSInterruptException ROSTimeMovedBackwardsException ROSSerializationException logdebug loginfo logwarn "
        "logerr logfatal loginfo_throttle logwarn_once logerr_throttle_identical get_param set_param has_param "
        "delete_param search_param get_param_names AnyMsg get_published_topics get_master DEBUG INFO WARN ERROR FATAL"
    ).split():
        assert hasattr(rospy, name), name
    assert rospy.Header is Header
    from rospy.numpy_msg import numpy_msg

    assert callable(numpy_msg)
    assert issubclass(rospy.ROSTimeMovedBackwardsException, rospy.ROSInterruptException)
    assert issubclass(rospy.ROSInterruptException, rospy.ROSException)
    assert (rospy.DEBUG, rospy.INFO, rospy.WARN, rospy.ERROR, rospy.FATAL) == (1, 2, 4, 8, 16)


@pytest.mark.parametrize(
    ("core", "expected"),
    [
        (errors.ShutdownError("x"), rospy.ROSInterruptException),
        (TimeMovedBackwardsError(5.0, 1.0), rospy.ROSTimeMovedBackwardsException),
        (errors.ServiceError("x"), rospy.ServiceException),
        (errors.SerializationError("x"), rospy.ROSSerializationException),
        (errors.TimeoutError_("x"), rospy.ROSException),
        (errors.MasterUnreachable("x"), rospy.ROSException),
        (errors.NameError_("x"), ValueError),
    ],
)
def test_core_errors_map_to_rospy_exceptions(core: Exception, expected: type) -> None:
    assert isinstance(translate(core), expected)
    plain = RuntimeError("not ours")
    assert translate(plain) is plain


def test_an_unreachable_master_raises_the_socket_error_as_rospy() -> None:
    refused = ConnectionRefusedError(111, "Connection refused")
    mapped = translate(errors.MasterUnreachable("cannot reach the master at http://h:1", cause=refused))
    assert type(mapped) is ConnectionRefusedError and str(mapped) == "[Errno 111] Connection refused"
    assert type(translate(errors.MasterUnreachable("t", cause=TimeoutError("timed out")))) is TimeoutError


class _HeaderOnly:
    _type = "test/HeaderOnly"
    _md5sum = "0" * 32
    _slot_types = ("std_msgs/Header",)
    __slots__ = ("header",)

    def __init__(self, header: object = None) -> None:
        self.header = header


def test_implicit_message_construction() -> None:
    assert args_kwds_to_message(String, ("hi",), {}) == String(data="hi")
    assert args_kwds_to_message(String, (), {"data": "kw"}) == String(data="kw")
    same = String(data="x")
    assert args_kwds_to_message(String, (same,), {}) is same
    with pytest.raises(TypeError, match="expected \\[string\\] but got \\[std_msgs/Int32\\]"):
        args_kwds_to_message(String, (Int32(1),), {})
    # a message whose first field has the given message's type wraps it, as in rospy
    from std_msgs.msg import Header

    stamped = args_kwds_to_message(_HeaderOnly, (Header(frame_id="f"),), {})
    assert stamped.header.frame_id == "f"
    with pytest.raises(TypeError, match="not both"):
        args_kwds_to_message(String, ("a",), {"data": "b"})


def test_any_msg_round_trip() -> None:
    raw = String(data="abc").serialize_to_bytes()
    msg = AnyMsg.deserialize_from(raw)
    assert msg.serialize_to_bytes() == raw
    buff = io.BytesIO()
    msg.serialize(buff)
    assert buff.getvalue() == raw
    with pytest.raises(rospy.ROSSerializationException):
        AnyMsg().serialize_to_bytes()


def test_numpy_msg_gives_arrays() -> None:
    import numpy

    from rospy.numpy_msg import numpy_msg
    from rospy_tutorials.msg import Floats

    cls = numpy_msg(Floats)
    assert numpy_msg(Floats) is cls and cls._type == "rospy_tutorials/Floats"
    data = Floats(data=[1.0, 2.5]).serialize_to_bytes()
    msg = cls.deserialize_from(data)
    assert isinstance(msg.data, numpy.ndarray) and list(msg.data) == [1.0, 2.5]
    out = cls(data=numpy.array([3.0, 4.0], dtype=numpy.float32))
    assert list(Floats.deserialize_from(out.serialize_to_bytes()).data) == [3.0, 4.0]


def test_state_before_init_node(capsys: pytest.CaptureFixture[str]) -> None:
    assert rospy.get_name() == "/unnamed"
    assert rospy.get_namespace() == "/"
    assert not rospy.is_shutdown()
    assert not rospy.core.is_initialized()
    assert abs(rospy.get_time() - time.time()) < 5
    assert rospy.resolve_name("chatter") == "/chatter"
    assert rospy.myargv(["prog", "a:=b", "_p:=1", "keep"]) == ["prog", "keep"]
    with pytest.raises(ConnectionRefusedError, match=r"^\[Errno 111\] Connection refused$"):
        rospy.get_param("x")  # as in rospy, allowed before init_node (as /unnamed): no master here
    pub = rospy.Publisher("chatter", String, queue_size=1)
    try:
        assert pub.get_num_connections() == 0
        assert pub.resolved_name == "/chatter" and pub.type == "std_msgs/String"
        with pytest.raises(rospy.ROSException, match="init_node\\(\\) first"):
            pub.publish("x")
    finally:
        pub.unregister()
    with pytest.raises(rospy.ROSException, match="unregistered"):
        pub.publish("x")
    rospy.loginfo("early %s", "bird")
    rospy.logwarn("careful")
    out, err = capsys.readouterr()
    assert out.startswith("[INFO] [") and out.rstrip().endswith("]: early bird")
    assert "[WARN]" in err and "careful" in err
    rate = rospy.Rate(200)
    start = time.monotonic()
    rate.sleep()
    rate.sleep()
    assert time.monotonic() - start >= 0.005
    rospy.sleep(rospy.Duration(0, 1_000_000))


def test_bad_handles_are_rejected() -> None:
    with pytest.raises(ValueError):
        rospy.Publisher("x", None)
    with pytest.raises(ValueError):
        rospy.Subscriber("", String)
    with pytest.raises(ValueError):
        rospy.ServiceProxy("s", String)
    with pytest.raises(ValueError, match="namespaces"):
        rospy.init_node("a/b")
    with pytest.raises(ValueError, match="empty"):
        rospy.init_node("")
