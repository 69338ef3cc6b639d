"""Packages Debian does not ship (gazebo_msgs, realsense2_camera, ...): Debian's own genmsg computes the
md5sum of each of our .msg/.srv files, resolving dependencies in our interface tree, and ours must be the
same. Our definitions are transcribed from the packages' Noetic sources; this checks our md5 code on
them with ROS 1's, for every type, and ``iface_published`` pins the ones ROS 1 itself published."""

from __future__ import annotations

import json
import subprocess

import pytest
from iface_inventory import INTERFACES, NOT_IN_DEBIAN, inventory, package_of

from ninjemys import testing
from ninjemys.idl.loader import get_message_class, get_service_class

pytestmark = pytest.mark.ros1

_GENMSG = r"""
import json, os, sys
import genmsg, genmsg.msg_loader, genmsg.gentools
root, types = sys.argv[1], json.loads(sys.argv[2])
paths = {p: [os.path.join(root, p, "msg")] for p in os.listdir(root)}
out = {}
for kind, name in types:
    ctx = genmsg.MsgContext.create_default()
    pkg, short = name.split("/")
    if kind == "msg":
        spec = genmsg.msg_loader.load_msg_by_type(ctx, name, paths)
    else:
        spec = genmsg.msg_loader.load_srv_from_file(ctx, os.path.join(root, pkg, "srv", short + ".srv"), name)
    genmsg.msg_loader.load_depends(ctx, spec, paths)
    out[name] = genmsg.gentools.compute_md5(ctx, spec)
print(json.dumps(out))
"""

INV = inventory()
TYPES = [("msg", t) for t in INV.messages if package_of(t) in NOT_IN_DEBIAN and "/" in t] + [
    ("srv", t) for t in INV.services if package_of(t) in NOT_IN_DEBIAN
]
# the generated action messages have no .msg file of their own
TYPES = [
    (k, t)
    for k, t in TYPES
    if k == "srv" or (INTERFACES / package_of(t) / "msg" / f"{t.split('/')[1]}.msg").exists()
]


@pytest.fixture(scope="module")
def genmsg_md5() -> dict[str, str]:
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 (genmsg) is not installed")
    done = subprocess.run(
        [testing.ROS1_PYTHON, "-c", _GENMSG, str(INTERFACES), json.dumps(TYPES)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return json.loads(done.stdout)


@pytest.mark.parametrize(("kind", "type_name"), TYPES, ids=[t for _, t in TYPES])
def test_md5_equals_debian_genmsg_on_the_same_text(
    kind: str, type_name: str, genmsg_md5: dict[str, str]
) -> None:
    ours = (get_message_class if kind == "msg" else get_service_class)(type_name)._md5sum
    assert ours == genmsg_md5[type_name]
