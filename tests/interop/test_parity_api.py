"""Our ROS 1 library facades against Debian's, name by name: every public module attribute, class,
method, signature (parameter names, kinds, defaults), constant and exception base that Debian's
actionlib, tf, tf2_ros, tf2_py, tf2_geometry_msgs, message_filters, dynamic_reconfigure,
laser_geometry and cv_bridge offer must be ours too, or be listed in ALLOWED with the reason it is not.

Each package is dumped by ``parity_surface.py`` in a fresh process under each interpreter, so what a
bare ``import tf`` makes reachable (``tf.transformations``) is compared as well.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ninjemys import testing

pytestmark = pytest.mark.ros1

DUMPER = str(Path(__file__).with_name("parity_surface.py"))

#: package -> the modules of it that ROS 1 programs import
PACKAGES = {
    "actionlib": [
        "actionlib",
        "actionlib.action_client",
        "actionlib.simple_action_client",
        "actionlib.action_server",
        "actionlib.simple_action_server",
        "actionlib.server_goal_handle",
        "actionlib.status_tracker",
        "actionlib.goal_id_generator",
        "actionlib.exceptions",
        "actionlib.handle_tracker_deleter",
        "actionlib.msg",
    ],
    "tf": ["tf", "tf.transformations", "tf.listener", "tf.broadcaster", "tf.msg", "tf.srv"],
    "tf2_ros": [
        "tf2_ros",
        "tf2_ros.buffer",
        "tf2_ros.buffer_interface",
        "tf2_ros.transform_listener",
        "tf2_ros.transform_broadcaster",
        "tf2_ros.static_transform_broadcaster",
        "tf2_ros.buffer_client",
    ],
    "tf2_py": ["tf2_py"],
    "tf2_geometry_msgs": ["tf2_geometry_msgs", "tf2_geometry_msgs.tf2_geometry_msgs"],
    "message_filters": ["message_filters"],
    "dynamic_reconfigure": [
        "dynamic_reconfigure",
        "dynamic_reconfigure.server",
        "dynamic_reconfigure.client",
        "dynamic_reconfigure.encoding",
        "dynamic_reconfigure.parameter_generator_catkin",
        "dynamic_reconfigure.msg",
        "dynamic_reconfigure.srv",
    ],
    "laser_geometry": ["laser_geometry", "laser_geometry.laser_geometry"],
    "cv_bridge": ["cv_bridge", "cv_bridge.core", "cv_bridge.boost.cv_bridge_boost"],
    "sensor_msgs": ["sensor_msgs.point_cloud2"],
    "PyKDL": ["PyKDL"],
    "tf_conversions": ["tf_conversions", "tf_conversions.posemath"],
}

_GENERATOR_INTERNALS = "the C++/Python/doc file writers behind generate(); ours generates differently"
_CSM = "CommStateMachine internals: ours is driven by the client with one status per goal, not the array"

#: what Debian has and we deliberately do not (or differently): path -> one-line reason
ALLOWED = {
    **{
        f"{mod}.{name}": "PyKDL: orocos-kdl's chains, trees, solvers, joint arrays and *Vel types are not"
        " provided; only the frames that tf_conversions and scripts use (docs/libs.md)"
        for mod in ("PyKDL", "tf_conversions", "tf_conversions.posemath")
        for name in (
            *("Add", "Subtract", "Multiply", "Divide", "MultiplyJacobian", "SolverI", "doubleVel"),
            *("Chain", "ChainDynParam", "ChainFkSolverPos", "ChainFkSolverPos_recursive", "ChainFkSolverVel"),
            *("ChainFkSolverVel_recursive", "ChainIdSolver", "ChainIdSolver_RNE", "ChainIkSolverPos"),
            *("ChainIkSolverPos_LMA", "ChainIkSolverPos_NR", "ChainIkSolverPos_NR_JL", "ChainIkSolverVel"),
            *("ChainIkSolverVel_pinv", "ChainIkSolverVel_pinv_givens", "ChainIkSolverVel_pinv_nso"),
            *("ChainIkSolverVel_wdls", "ChainJntToJacDotSolver", "ChainJntToJacSolver", "FrameVel"),
            *("Jacobian", "JntArray", "JntArrayVel", "JntSpaceInertiaMatrix", "Joint", "RigidBodyInertia"),
            *("RotationVel", "RotationalInertia", "Segment", "Tree", "TwistVel", "VectorVel"),
        )
    },
    **{
        f"{mod}.{cls}": "PyKDL's classes are pybind11 objects there, plain Python classes here"
        for mod in ("PyKDL", "tf_conversions", "tf_conversions.posemath")
        for cls in ("Frame", "Rotation", "Vector", "Twist", "Wrench")
    },
    "actionlib.g_goal_id": "a module-level counter of ROS 1's client; our ids come from GoalIDGenerator",
    "actionlib.action_client.g_goal_id": "same counter as actionlib.g_goal_id",
    "actionlib.goal_id_generator.s_goalcount": "ROS 1's module-level goal counter; ours lives in the generator",
    "actionlib.goal_id_generator.s_goalcount_lock": "the lock of that counter",
    "actionlib.CommStateMachine.__init__": _CSM + " (it also takes the client's log)",
    "actionlib.CommStateMachine.update_status": _CSM,
    "actionlib.action_client.CommStateMachine.__init__": _CSM + " (it also takes the client's log)",
    "actionlib.action_client.CommStateMachine.update_status": _CSM,
    **{
        f"{mod}.GoalManager.{m}": "ours keeps the goals inside ActionClient; GoalManager only names the types"
        for mod in ("actionlib", "actionlib.action_client")
        for m in (
            "init_goal",
            "register_cancel_fn",
            "register_send_goal_fn",
            "update_feedbacks",
            "update_results",
            "update_statuses",
        )
    },
    "tf2_ros.deepcopy": "copy.deepcopy leaking from ROS 1's star import",
    "tf2_ros.buffer_interface.deepcopy": "copy.deepcopy leaking from ROS 1's imports",
    "tf2_ros.TypeException": "ours is also a TransformException (one root for tf2's errors); a superset",
    "tf2_ros.buffer_interface.TypeException": "see tf2_ros.TypeException",
    "tf2_geometry_msgs.transform_to_kdl": "returns a PyKDL.Frame; ours computes with numpy, PyKDL is not a dependency",
    "tf2_geometry_msgs.tf2_geometry_msgs.transform_to_kdl": "see tf2_geometry_msgs.transform_to_kdl",
    "message_filters.reduce": "functools.reduce leaking from ROS 1's imports",
    "sensor_msgs.point_cloud2.ctypes": "a module ROS 1's create_cloud uses, leaking",
    "sensor_msgs.point_cloud2.math": "a module leaking from ROS 1's imports",
    "sensor_msgs.point_cloud2.namedtuple": "collections.namedtuple leaking from ROS 1's imports",
    "sensor_msgs.point_cloud2.roslib": "a module leaking from ROS 1's imports",
    "sensor_msgs.point_cloud2.struct": "a module leaking from ROS 1's imports",
    "dynamic_reconfigure.parameter_generator_catkin.LINEDEBUG": _GENERATOR_INTERNALS,
    "dynamic_reconfigure.parameter_generator_catkin.Template": "string.Template leaking from ROS 1's imports",
    "dynamic_reconfigure.parameter_generator_catkin.id": "the generator's group id counter, internal",
    "dynamic_reconfigure.parameter_generator_catkin.check_description": _GENERATOR_INTERNALS,
    "dynamic_reconfigure.parameter_generator_catkin.check_name": _GENERATOR_INTERNALS,
    **{
        f"dynamic_reconfigure.parameter_generator_catkin.ParameterGenerator.{m}": _GENERATOR_INTERNALS
        for m in (
            "appendgroup",
            "appendline",
            "check_type",
            "check_type_fill_default",
            "crepr",
            "defval",
            "fill_type",
            "generatecpp",
            "generatedoc",
            "generatepy",
            "generateusage",
            "generatewikidoc",
            "maxval",
            "minval",
            "mkdirabs",
            "pytype",
            "replace_infinity",
        )
    },
    "tf2_py.BufferCore.__init__": "a C++ class in ROS 1 (*args); ours names its one argument, cache_time",
    "tf2_ros.BufferCore.__init__": "see tf2_py.BufferCore.__init__",
}

#: Python 2 leftovers that leak into ROS 1's modules: ``from __future__`` names, and genpy's
#: ``python3`` flag (star-imported from every generated message module)
FUTURE = {"absolute_import", "division", "print_function", "with_statement", "unicode_literals", "python3"}
#: a root every ninjemys error shares; an extra base, so ``except`` clauses behave as in ROS 1
EXTRA_BASES = {"NinjemysError"}
#: zero, None and rospy.Duration(0) all mean "no timeout" in ROS 1's timeouts
ZERO_TIMEOUT = {"rospy.Duration[0]", "0.0", "0", "None"}


def dump(python: str, package: str, env: dict[str, str] | None) -> dict:
    done = subprocess.run(
        [python, DUMPER, package, *PACKAGES[package]],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        cwd="/",
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def _default(name: str, default: str | None) -> str | None:
    if default is None:
        return None
    default = re.sub(r" at 0x[0-9a-f]+", "", default)
    if "timeout" in name and default in ZERO_TIMEOUT:
        return "<no timeout>"
    if default in ("()", "[]"):
        return "<empty>"  # ROS 1's mutable [] default and our () behave alike
    return default


def _same_signature(theirs: list | None, ours: list | None) -> bool:
    """Same parameters (names, kinds, defaults), or ROS 1's followed only by optional extras of ours."""
    if theirs is None or ours is None:
        return True  # C++ functions have no signature to compare: present is enough
    a, b = _params(theirs), _params(ours)
    extras = b[len(a) :]
    return b[: len(a)] == a and all(d is not None or k.startswith("VAR") for _n, k, d in extras)


def _params(sig: list | None) -> list | None:
    if sig is None:
        return None
    out = []
    for i, (name, kind, default) in enumerate(sig):
        if i == 0 and name == "self":
            kind = "POSITIONAL_OR_KEYWORD"  # C++ methods report self as positional-only
        out.append((name, kind, _default(name, default)))
    return out


def _in_package(cls_module: str, package: str) -> bool:
    """Whether a class is the package's own (not a message class or another package's)."""
    if ".msg." in cls_module or ".srv." in cls_module:
        return False
    return cls_module.split(".")[0] == package or cls_module.startswith(("tf2_py", "_tf2", "tf2_ros"))


def differences(package: str, theirs: dict, ours: dict) -> list[str]:
    problems: list[str] = []
    for sub in theirs["<submodules>"]:
        if sub.startswith("_"):
            continue  # the compiled core (tf2_py._tf2): private
        if sub not in ours["<submodules>"] and f"{package}.{sub}" not in ALLOWED:
            problems.append(f"`import {package}` does not make {package}.{sub} reachable")
    for mod in PACKAGES[package]:
        their_mod, our_mod = theirs[mod], ours.get(mod, {})
        if "<error>" in their_mod:
            continue
        if "<error>" in our_mod:
            if mod not in ALLOWED:
                problems.append(f"{mod}: {our_mod['<error>']}")
            continue
        for name, t in their_mod.items():
            path = f"{mod}.{name}"
            if name in FUTURE or path in ALLOWED or t["kind"] == "module":
                continue
            o = our_mod.get(name)
            if o is None:
                problems.append(f"{path}: missing ({t['kind']})")
            elif t["kind"] == "class":
                problems.extend(_class_differences(path, package, t, o))
            elif t["kind"] == "function":
                if o["kind"] not in ("function", "class"):
                    problems.append(f"{path}: a {o['kind']}, not a function")
                elif not _same_signature(t["sig"], o.get("sig")):
                    problems.append(f"{path}: signature {o['sig']} != {t['sig']}")
            elif o.get("value") != t["value"] and not _same_number(o.get("value"), t["value"]):
                problems.append(f"{path}: value {o.get('value')} != {t['value']}")
    return problems


def _same_number(a: str | None, b: str) -> bool:
    try:
        return a is not None and float(a) == float(b)
    except ValueError:
        return False


def _class_differences(path: str, package: str, t: dict, o: dict) -> list[str]:
    if o["kind"] != "class":
        return [f"{path}: a {o['kind']}, not a class"]
    if not _in_package(t["module"], package):
        return []  # a message class or another package's, re-exported: present is enough
    problems = []
    our_bases = [b for b in o["bases"] if b not in EXTRA_BASES]
    their_bases = set(t["bases"])
    if not their_bases <= set(our_bases) and path not in ALLOWED:
        problems.append(f"{path}: bases {our_bases} lack {sorted(their_bases - set(our_bases))}")
    if t["bases"] and t["bases"][0] in ("Exception", "TypeError", "RuntimeError") and path not in ALLOWED:
        if our_bases[: len(t["bases"])] != t["bases"] and our_bases != t["bases"]:
            problems.append(f"{path}: exception bases {our_bases} != {t['bases']}")
    for name, tm in t["members"].items():
        mpath = f"{path}.{name}"
        if mpath in ALLOWED:
            continue
        om = o["members"].get(name)
        if om is None:
            problems.append(f"{mpath}: missing ({tm['kind']})")
        elif tm["kind"] == "method" and om["kind"] == "attr":
            problems.append(f"{mpath}: an attribute, not a method")
        elif tm.get("sig") is not None and om.get("sig") is not None:
            if not _same_signature(tm["sig"], om["sig"]):
                problems.append(f"{mpath}: signature {om['sig']} != {tm['sig']}")
        elif (
            tm["kind"] == "attr"
            and om.get("value") != tm["value"]
            and not _same_number(om.get("value"), tm["value"])
        ):
            problems.append(f"{mpath}: value {om.get('value')} != {tm['value']}")
    return problems


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_public_surface_matches_ros1(package: str) -> None:
    theirs = dump(testing.ROS1_PYTHON, package, testing.ros1_env("http://localhost:11311"))
    ours = dump(sys.executable, package, None)
    problems = differences(package, theirs, ours)
    assert not problems, "\n".join(problems)


def test_allow_list_names_only_real_differences() -> None:
    """Every allowance is for something Debian has (a stale entry would hide a future regression)."""
    theirs = {p: dump(testing.ROS1_PYTHON, p, testing.ros1_env("http://localhost:11311")) for p in PACKAGES}
    known = set()
    for package, dumped in theirs.items():
        known |= {f"{package}.{s}" for s in dumped["<submodules>"]}
        for mod, names in dumped.items():
            if mod == "<submodules>" or "<error>" in names:
                continue
            for name, t in names.items():
                known.add(f"{mod}.{name}")
                known |= {f"{mod}.{name}.{m}" for m in t.get("members", {})}
    assert set(ALLOWED) <= known, sorted(set(ALLOWED) - known)
