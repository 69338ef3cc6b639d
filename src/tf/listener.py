"""tf's legacy listener API (``Transformer``, ``TransformerROS``, ``TransformListener``) over tf2_ros.

Same names and return shapes as ROS 1's tf (lookups return ``([x, y, z], [qx, qy, qz, qw])``;
leading slashes in frame ids are stripped), with tf2's exceptions.
"""

from __future__ import annotations

from typing import Any

import numpy

import tf2_ros
from ninjemys.tf2 import math as tfm
from ninjemys.tf2 import transformations
from ninjemys.tf2.buffer import make_time, to_ns, to_seconds


def strip_leading_slash(s: str) -> str:
    return s[1:] if s.startswith("/") else s


def xyz_to_mat44(pos: Any) -> Any:
    return transformations.translation_matrix((pos.x, pos.y, pos.z))


def xyzw_to_mat44(ori: Any) -> Any:
    return transformations.quaternion_matrix((ori.x, ori.y, ori.z, ori.w))


class Transformer:
    """A tf buffer with the legacy camelCase API."""

    def __init__(self, interpolate: bool = True, cache_time: Any = None) -> None:
        self._buffer = tf2_ros.Buffer(cache_time, debug=False)
        self._using_dedicated_thread = False

    def allFramesAsDot(self, current_time: Any = None) -> str:  # noqa: N802
        return self._buffer._allFramesAsDot(current_time)

    def allFramesAsString(self) -> str:  # noqa: N802
        return self._buffer.all_frames_as_string()

    def setTransform(self, transform: Any, authority: str = "default_authority") -> None:  # noqa: N802
        self._buffer.set_transform(transform, authority)

    def canTransform(self, target_frame: str, source_frame: str, time: Any) -> bool:  # noqa: N802
        return self._buffer.can_transform(
            strip_leading_slash(target_frame), strip_leading_slash(source_frame), time
        )

    def canTransformFull(  # noqa: N802
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> bool:
        return self._buffer.can_transform_full(
            strip_leading_slash(target_frame),
            target_time,
            strip_leading_slash(source_frame),
            source_time,
            strip_leading_slash(fixed_frame),
        )

    def _need_thread(self) -> None:
        if not self._using_dedicated_thread:
            raise tf2_ros.TransformException(
                "cannot wait for transform without a dedicated thread that listens to incoming TF messages"
            )

    def waitForTransform(  # noqa: N802
        self,
        target_frame: str,
        source_frame: str,
        time: Any,
        timeout: Any,
        polling_sleep_duration: Any = None,
    ) -> None:
        """Wait up to ``timeout`` for the transform (woken by new data); TransformException if it never comes."""
        self._need_thread()
        ok, why = self._buffer.can_transform(
            strip_leading_slash(target_frame),
            strip_leading_slash(source_frame),
            time,
            timeout,
            return_debug_tuple=True,
        )
        if not ok:
            raise tf2_ros.TransformException(
                why or f'no such transformation: "{source_frame}" -> "{target_frame}"'
            )

    def waitForTransformFull(  # noqa: N802
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any,
        polling_sleep_duration: Any = None,
    ) -> None:
        self._need_thread()
        ok, why = self._buffer.can_transform_full(
            strip_leading_slash(target_frame),
            target_time,
            strip_leading_slash(source_frame),
            source_time,
            strip_leading_slash(fixed_frame),
            timeout,
            return_debug_tuple=True,
        )
        if not ok:
            raise tf2_ros.TransformException(
                why or f'no such transformation: "{source_frame}" -> "{target_frame}"'
            )

    def chain(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> Any:
        return self._buffer._chain(target_frame, target_time, source_frame, source_time, fixed_frame)

    def clear(self) -> None:
        self._buffer.clear()

    def frameExists(self, frame_id: str) -> bool:  # noqa: N802
        """Whether ``frame_id`` is a child frame with data (ROS 1 reads the YAML listing)."""
        return frame_id in self.getFrameStrings()

    def getFrameStrings(self) -> list[str]:  # noqa: N802
        """The child frames that have data (the keys of ``all_frames_as_yaml``, as ROS 1's tf returns)."""
        return self._buffer.child_frames()

    def getLatestCommonTime(self, source_frame: str, dest_frame: str) -> Any:  # noqa: N802
        return self._buffer.get_latest_common_time(
            strip_leading_slash(source_frame), strip_leading_slash(dest_frame)
        )

    def lookupTransform(self, target_frame: str, source_frame: str, time: Any) -> tuple[list, list]:  # noqa: N802
        """``([x, y, z], [qx, qy, qz, qw])`` from ``source_frame`` to ``target_frame``."""
        _, t = self._buffer.lookup(
            strip_leading_slash(target_frame), strip_leading_slash(source_frame), to_ns(time)
        )
        return [t[0], t[1], t[2]], [t[3], t[4], t[5], t[6]]

    def lookupTransformFull(  # noqa: N802
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> tuple[list, list]:
        _, t = self._buffer.lookup_full(
            strip_leading_slash(target_frame),
            to_ns(target_time),
            strip_leading_slash(source_frame),
            to_ns(source_time),
            strip_leading_slash(fixed_frame),
        )
        return [t[0], t[1], t[2]], [t[3], t[4], t[5], t[6]]

    def lookupTwist(  # noqa: N802
        self, tracking_frame: str, observation_frame: str, time: Any, averaging_interval: Any
    ) -> tuple[tuple, tuple]:
        return self.lookupTwistFull(
            tracking_frame,
            observation_frame,
            observation_frame,
            (0, 0, 0),
            tracking_frame,
            time,
            averaging_interval,
        )

    def lookupTwistFull(  # noqa: N802
        self,
        tracking_frame: str,
        observation_frame: str,
        reference_frame: str,
        ref_point: Any,
        reference_point_frame: str,
        time: Any,
        averaging_interval: Any,
    ) -> tuple[tuple, tuple]:
        """Linear and angular velocity of ``tracking_frame`` relative to ``observation_frame``, averaged
        over ``averaging_interval`` around ``time``, expressed in ``reference_frame`` at ``ref_point``."""
        latest = to_ns(self.getLatestCommonTime(observation_frame, tracking_frame))
        target = to_ns(time) or latest
        half = int(to_seconds(averaging_interval) * 0.5e9)
        interval = int(to_seconds(averaging_interval) * 1e9)
        end = min(target + half, latest)
        start = max(100_000 + interval, end) - interval
        dt = (end - start) / 1e9
        start_t, start_q = self.lookupTransform(observation_frame, tracking_frame, make_time(start))
        end_t, end_q = self.lookupTransform(observation_frame, tracking_frame, make_time(end))
        dq = tfm.quaternion_multiply((-start_q[0], -start_q[1], -start_q[2], start_q[3]), tuple(end_q))
        angle, axis, _ = transformations.rotation_from_matrix(transformations.quaternion_matrix(dq))
        vel0 = numpy.array([(e - s) / dt for s, e in zip(start_t, end_t, strict=True)])
        rot0 = numpy.asarray(axis) * angle / dt
        inv_t, inv_q = self.lookupTransform(reference_frame, tracking_frame, make_time(target))
        r = transformations.quaternion_matrix(inv_q)[:3, :3]
        rot = r @ rot0
        vel = r @ vel0 + numpy.cross(inv_t, rot)
        origin = numpy.array((inv_t[0], inv_t[1], inv_t[2], 1.0))
        rp_t, rp_q = self.lookupTransform(reference_frame, reference_point_frame, make_time(target))
        m = transformations.translation_matrix(rp_t) @ transformations.quaternion_matrix(rp_q)
        delta = m @ numpy.array((origin[0], origin[1], origin[2], 1.0)) - origin
        # ROS 1 adds the dot product of rot and delta to every component (not the cross product a
        # lever arm would give); programs compare against that, so it is kept
        vel = vel + float(numpy.dot(rot, delta[:3]))
        return (vel[0], vel[1], vel[2]), (rot[0], rot[1], rot[2])  # numpy floats, as ROS 1 returns

    def setUsingDedicatedThread(self, value: bool) -> None:  # noqa: N802
        self._using_dedicated_thread = value

    def getTFPrefix(self) -> str:  # noqa: N802
        """tf2 has no tf_prefix: always ''."""
        return ""


class TransformerROS(Transformer):
    """Adds transforms of geometry_msgs stamped types and 4x4 matrices."""

    def asMatrix(self, target_frame: str, hdr: Any) -> Any:  # noqa: N802
        """The 4x4 matrix from ``hdr.frame_id`` at ``hdr.stamp`` to ``target_frame``."""
        translation, rotation = self.lookupTransform(target_frame, hdr.frame_id, hdr.stamp)
        return self.fromTranslationRotation(translation, rotation)

    def fromTranslationRotation(self, translation: Any, rotation: Any) -> Any:  # noqa: N802
        return numpy.dot(
            transformations.translation_matrix(translation), transformations.quaternion_matrix(rotation)
        )

    def _lookup(self, target_frame: str, header: Any) -> tuple:
        _, t = self._buffer.lookup(
            strip_leading_slash(target_frame), strip_leading_slash(header.frame_id), to_ns(header.stamp)
        )
        return t

    @staticmethod
    def _stamped(msg: Any, target_frame: str, field: str, value: Any) -> Any:
        out = type(msg)()
        out.header.stamp = msg.header.stamp
        out.header.frame_id = target_frame
        setattr(out, field, value)
        return out

    def transformPoint(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        """A ``PointStamped`` in ``target_frame`` (at the point's stamp)."""
        t = self._lookup(target_frame, ps.header)
        p = type(ps.point)(*tfm.transform_point(t, ps.point.x, ps.point.y, ps.point.z))
        return self._stamped(ps, target_frame, "point", p)

    def transformVector3(self, target_frame: str, v3s: Any) -> Any:  # noqa: N802
        t = self._lookup(target_frame, v3s.header)
        v = v3s.vector
        return self._stamped(v3s, target_frame, "vector", type(v)(*tfm.rotate_vector(*t[3:], v.x, v.y, v.z)))

    def transformQuaternion(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        t = self._lookup(target_frame, ps.header)
        q = ps.quaternion
        r = tfm.quaternion_multiply(t[3:], (q.x, q.y, q.z, q.w))
        return self._stamped(ps, target_frame, "quaternion", type(q)(*r))

    def transformPose(self, target_frame: str, ps: Any) -> Any:  # noqa: N802
        t = self._lookup(target_frame, ps.header)
        p, o = ps.pose.position, ps.pose.orientation
        pose = type(ps.pose)(
            type(p)(*tfm.transform_point(t, p.x, p.y, p.z)),
            type(o)(*tfm.quaternion_multiply(t[3:], (o.x, o.y, o.z, o.w))),
        )
        return self._stamped(ps, target_frame, "pose", pose)

    def transformPointCloud(self, target_frame: str, point_cloud: Any) -> Any:  # noqa: N802
        """A ``sensor_msgs/PointCloud`` with every point moved into ``target_frame`` (channels kept)."""
        t = self._lookup(target_frame, point_cloud.header)
        out = type(point_cloud)()
        out.header.stamp = point_cloud.header.stamp
        out.header.frame_id = target_frame
        out.channels = point_cloud.channels
        if point_cloud.points:
            cls = type(point_cloud.points[0])
            out.points = [cls(*tfm.transform_point(t, p.x, p.y, p.z)) for p in point_cloud.points]
        return out


class TransformListener(TransformerROS):
    """A ``TransformerROS`` filled from ``/tf`` and ``/tf_static`` (needs ``rospy.init_node`` first)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        TransformerROS.__init__(self, *args, **kwargs)
        self._listener = tf2_ros.TransformListener(self._buffer)
        self.setUsingDedicatedThread(True)
