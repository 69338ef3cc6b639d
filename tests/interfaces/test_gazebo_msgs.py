"""gazebo_msgs complete and wire-identical to Noetic's: Debian packages no gazebo_msgs, so Debian's own
genmsg (under /usr/bin/python3) computes every md5sum from our shipped text, with Debian's classes
standing in for the geometry_msgs/std_msgs/trajectory_msgs types they refer to; ours must agree, and
the published md5sums (iface_published.py) anchor a sample independently of both."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from iface_inventory import INTERFACES, inventory, package_of
from iface_published import PUBLISHED_MD5

from ninjemys.idl.loader import get_message_class, get_service_class

ORACLE = Path(__file__).with_name("gazebo_md5_oracle.py")

#: Noetic's gazebo_msgs (gazebo_ros_pkgs 2.9): 11 messages and 23 services
NOETIC_MESSAGES = {
    "ContactState", "ContactsState", "LinkState", "LinkStates", "ModelState", "ModelStates",
    "ODEJointProperties", "ODEPhysics", "PerformanceMetrics", "SensorPerformanceMetric", "WorldState",
}  # fmt: skip
NOETIC_SERVICES = {
    "ApplyBodyWrench", "ApplyJointEffort", "BodyRequest", "DeleteLight", "DeleteModel",
    "GetJointProperties", "GetLightProperties", "GetLinkProperties", "GetLinkState",
    "GetModelProperties", "GetModelState", "GetPhysicsProperties", "GetWorldProperties", "JointRequest",
    "SetJointProperties", "SetJointTrajectory", "SetLightProperties", "SetLinkProperties", "SetLinkState",
    "SetModelConfiguration", "SetModelState", "SetPhysicsProperties", "SpawnModel",
}  # fmt: skip


def test_every_noetic_gazebo_type_is_shipped() -> None:
    inv = inventory()
    assert {t.split("/")[1] for t in inv.messages if package_of(t) == "gazebo_msgs"} == NOETIC_MESSAGES
    assert {t.split("/")[1] for t in inv.services if package_of(t) == "gazebo_msgs"} == NOETIC_SERVICES


@pytest.fixture(scope="module")
def genmsg_md5() -> dict[str, str]:
    out = subprocess.run(
        ["/usr/bin/python3", str(ORACLE), str(INTERFACES)], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.ros1
def test_debian_genmsg_computes_our_md5sums(genmsg_md5: dict[str, str]) -> None:
    assert set(genmsg_md5) == {f"gazebo_msgs/{n}" for n in NOETIC_MESSAGES | NOETIC_SERVICES}
    for type_name, md5 in genmsg_md5.items():
        name = type_name.split("/")[1]
        cls = get_message_class(type_name) if name in NOETIC_MESSAGES else get_service_class(type_name)
        assert cls._md5sum == md5, type_name


@pytest.mark.ros1
def test_the_published_md5sums_agree_with_debian_genmsg(genmsg_md5: dict[str, str]) -> None:
    published = {t: m for t, m in PUBLISHED_MD5.items() if t.startswith("gazebo_msgs/")}
    assert len(published) >= 8
    for type_name, md5 in published.items():
        assert genmsg_md5[type_name] == md5, type_name


def test_constants_of_get_joint_properties() -> None:
    resp = get_service_class("gazebo_msgs/GetJointProperties")._response_class
    assert (resp.REVOLUTE, resp.CONTINUOUS, resp.FIXED, resp.UNIVERSAL) == (0, 1, 3, 5)
