"""Run under either interpreter: tf_conversions.posemath on random poses, printed as JSON."""

import json
import random

import numpy

import tf_conversions.posemath as pm
from geometry_msgs.msg import Pose


class FakeCv:
    """The legacy ``cv`` module's Rodrigues2, enough for fromCameraParams (via tf.transformations)."""

    @staticmethod
    def Rodrigues2(rvec, dst):
        from tf import transformations

        v = numpy.array([rvec[0, 0], rvec[1, 0], rvec[2, 0]], dtype=float)
        angle = float(numpy.linalg.norm(v))
        dst[:] = transformations.rotation_matrix(angle, v / angle)[:3, :3] if angle else numpy.eye(3)


def main():
    rng = random.Random(11)
    rows = []
    for _ in range(100):
        q = numpy.array([rng.uniform(-1, 1) for _ in range(4)])
        q /= numpy.linalg.norm(q)
        t = tuple(rng.uniform(-5, 5) for _ in range(3))
        f = pm.fromTf((t, tuple(q)))
        msg = Pose()
        msg.position.x, msg.position.y, msg.position.z = t
        msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = q
        g = pm.fromMsg(msg)
        back = pm.toMsg(f * g)
        m = pm.toMatrix(f)
        rvec = numpy.array([[rng.uniform(-2, 2)] for _ in range(3)])
        tvec = numpy.array([[rng.uniform(-2, 2)] for _ in range(3)])
        cam = pm.fromCameraParams(FakeCv, rvec, tvec)
        rows.append(
            {
                "toTf": [list(pm.toTf(f)[0]), list(pm.toTf(f)[1])],
                "msg": [back.position.x, back.position.y, back.position.z]
                + [back.orientation.x, back.orientation.y, back.orientation.z, back.orientation.w],
                "matrix": m.tolist(),
                "roundtrip": pm.toMatrix(pm.fromMatrix(m @ m)).tolist(),
                "cam": pm.toMatrix(cam).tolist(),
                "type": type(back).__name__ + type(m).__name__,
            }
        )
    names = sorted(
        n for n in ("Frame", "Vector", "Rotation", "Twist", "Pose", "Point", "Quaternion") if hasattr(pm, n)
    )
    print(json.dumps({"rows": rows, "names": names}))


if __name__ == "__main__":
    main()
