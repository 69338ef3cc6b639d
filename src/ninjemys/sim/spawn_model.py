"""``rosrun gazebo_ros spawn_model``: put a model into the running simulator through Gazebo's services.

gazebo_ros' options and log lines: ``-urdf``/``-sdf`` (one required), the XML from ``-file PATH``,
``-param NAME``, ``-database MODEL`` or ``-stdin``, ``-model NAME`` (required), ``-x -y -z -R -P -Y``,
``-reference_frame``, ``-gazebo_namespace`` (default ``/gazebo``), ``-robot_namespace`` (default: the
node's namespace), ``-J JOINT POSITION`` (repeatable, via set_model_configuration), ``-unpause``,
``-wait MODEL`` (until it shows in ``model_states``), ``-package_to_model`` and ``-b`` (delete the
model again on Ctrl-C). It exits 0 once the model is in, 1 with gazebo_ros' error line otherwise.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
import xml.etree.ElementTree as ET
from typing import Any
from urllib.parse import SplitResult, urlsplit

from ninjemys.commands import entry
from ninjemys.errors import NinjemysError, ShutdownError, TimeoutError_
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.names import rospy_anonymous_name
from ninjemys.node import Node
from ninjemys.node.run import start_node
from ninjemys.tf2.math import quaternion_from_rpy

Empty: Any = get_service_class("std_srvs/Empty")
SpawnModel: Any = get_service_class("gazebo_msgs/SpawnModel")
DeleteModel: Any = get_service_class("gazebo_msgs/DeleteModel")
SetModelConfiguration: Any = get_service_class("gazebo_msgs/SetModelConfiguration")
ModelStates: Any = get_message_class("gazebo_msgs/ModelStates")

DATABASE_TEMPLATE = (
    '<sdf version="1.4"><world name="default"><include><uri>model://{}</uri></include></world></sdf>'
)


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="spawn_model", description="Spawn a model in gazebo using the ROS API")
    fmt = p.add_mutually_exclusive_group(required=True)
    fmt.add_argument("-urdf", action="store_true", help="Incoming xml is in urdf format")
    fmt.add_argument("-sdf", action="store_true", help="Incoming xml is in sdf format")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("-file", type=str, metavar="FILE_NAME", help="Load model xml from file")
    source.add_argument("-param", type=str, metavar="PARAM_NAME", help="Load model xml from ROS parameter")
    source.add_argument(
        "-database", type=str, metavar="MODEL_NAME", help="Load model XML from a model:// name"
    )
    source.add_argument("-stdin", action="store_true", help="Load model from stdin")
    p.add_argument("-model", required=True, type=str, metavar="MODEL_NAME", help="Name of model to spawn")
    p.add_argument(
        "-reference_frame", type=str, default="", help="Model/body the initial pose is relative to"
    )
    p.add_argument("-gazebo_namespace", type=str, default="/gazebo", help="Namespace of Gazebo's ROS API")
    p.add_argument("-robot_namespace", type=str, default=None, help="ROS namespace of the model's plugins")
    p.add_argument("-unpause", action="store_true", help="unpause physics after spawning model")
    p.add_argument("-wait", type=str, metavar="MODEL_NAME", help="wait for model to exist")
    for axis, what in (("x", "x"), ("y", "y"), ("z", "z")):
        p.add_argument(
            f"-{axis}", type=float, default=0.0, help=f"{what} component of initial position, meters"
        )
    for axis, what in (("R", "roll"), ("P", "pitch"), ("Y", "yaw")):
        p.add_argument(
            f"-{axis}", type=float, default=0.0, help=f"{what} angle of initial orientation, radians"
        )
    p.add_argument(
        "-J",
        dest="joints",
        default=[],
        action="append",
        metavar=("JOINT_NAME", "JOINT_POSITION"),
        type=str,
        nargs=2,
        help="initialize the specified joint at the specified position",
    )
    p.add_argument("-package_to_model", action="store_true", help="package:// mesh URIs become model://")
    p.add_argument("-b", dest="bond", action="store_true", help="delete the model when interrupted")
    return p


def read_model_xml(node: Node, args: argparse.Namespace) -> str | None:
    """The model's XML from the chosen source; None after logging gazebo_ros' error line."""
    log = node.log
    if args.file:
        log.info("Loading model XML from file %s", args.file)
        if not os.path.exists(args.file):
            log.fatal("Error: specified file %s does not exist", args.file)
            return None
        if not os.path.isfile(args.file):
            log.fatal("Error: specified file %s is not a file", args.file)
            return None
        try:
            with open(args.file, encoding="utf-8") as f:
                text = f.read()
        except OSError as exc:
            log.error("Error reading file %s: %s", args.file, exc)
            return None
        if text == "":
            log.error("Error: file %s is empty", args.file)
            return None
        return text
    if args.param:
        log.info("Loading model XML from ros parameter %s", args.param)
        value = node.get_param(args.param, "") if node.has_param(args.param) else ""
        if value == "" or not isinstance(value, str):
            log.error("Error: param does not exist or is empty")
            return None
        return value
    if args.database:
        log.info("Loading model XML from Gazebo Model Database")
        return DATABASE_TEMPLATE.format(args.database)
    log.info("Loading model XML from stdin")
    text = sys.stdin.read()
    if text == "":
        log.error("Error: stdin buffer was empty")
        return None
    return text


def prepare_xml(text: str, package_to_model: bool) -> str:
    """Parse (invalid XML is refused before Gazebo sees it) and rewrite mesh URIs if asked."""
    root = ET.fromstring(text)
    if package_to_model:
        for mesh in root.iter("mesh"):
            filename = mesh.get("filename")
            if filename is None:
                continue
            url = urlsplit(filename)
            if url.scheme == "package":
                mesh.set("filename", SplitResult("model", *url[1:]).geturl())
    return ET.tostring(root, encoding="unicode")


def wait_for_model(node: Node, topic: str, model: str) -> bool:
    """Block until ``model`` is in ``topic`` (ModelStates); False when the node shut down first."""
    seen = threading.Event()
    sub = node.subscriber(topic, ModelStates, lambda msg: seen.set() if model in msg.name else None)
    node.log.info("Waiting for model %s before proceeding.", model)
    try:
        while not seen.wait(0.1):
            if node.is_shutdown:
                return False
        return True
    finally:
        sub.unregister()


def wait_for_service(node: Node, name: str) -> None:
    """Until ``name`` answers, asking every 50 ms at most: a launch file starts spawn_model beside
    gzserver, and the model should go in as soon as the server offers the service (the core's
    wait backs off to 200 ms between tries)."""
    while True:
        try:
            node.wait_for_service(name, 0.05)
            return
        except TimeoutError_:
            continue


def call(node: Node, name: str, cls: Any, **fields: Any) -> Any:
    wait_for_service(node, name)
    req = cls._request_class()
    for key, value in fields.items():
        setattr(req, key, value)
    return node.service_proxy(name, cls)(req)


def run(node: Node, args: argparse.Namespace) -> int:
    log = node.log
    ns = args.gazebo_namespace.rstrip("/")
    if args.wait and not wait_for_model(node, f"{ns}/model_states", args.wait):
        return 0
    text = read_model_xml(node, args)
    if text is None:
        return 1
    try:
        model_xml = prepare_xml(text, args.package_to_model)
    except ET.ParseError as exc:
        log.error("Invalid XML: %s", exc)
        return 1
    fields: dict[str, Any] = {
        "model_name": args.model,
        "model_xml": model_xml,
        "robot_namespace": args.robot_namespace if args.robot_namespace is not None else node.namespace,
        "reference_frame": args.reference_frame,
    }
    req = SpawnModel._request_class()
    pose = req.initial_pose
    pose.position.x, pose.position.y, pose.position.z = args.x, args.y, args.z
    q = quaternion_from_rpy(args.R, args.P, args.Y)
    pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = q
    fields["initial_pose"] = pose
    service = f"{ns}/spawn_urdf_model" if args.urdf else f"{ns}/spawn_sdf_model"
    log.info("Waiting for service %s", service)
    try:
        wait_for_service(node, service)
        log.info("Calling service %s", service)
        resp = call(node, service, SpawnModel, **fields)
        log.info("Spawn status: %s", resp.status_message)
    except ShutdownError:
        return 1
    except NinjemysError as exc:
        print(f"Service call failed: {exc}", flush=True)
        resp = None
    if resp is None or not resp.success:
        log.error("Spawn service failed. Exiting.")
        return 1
    if args.joints:
        try:
            joints = [(name, float(value)) for name, value in args.joints]
        except ValueError as exc:
            log.error("-J: %s", exc)
            return 1
        try:
            resp = call(
                node,
                f"{ns}/set_model_configuration",
                SetModelConfiguration,
                model_name=args.model,
                urdf_param_name="",
                joint_names=[j for j, _ in joints],
                joint_positions=[v for _, v in joints],
            )
            log.info("Set model configuration status: %s", resp.status_message)
            ok = resp.success
        except NinjemysError as exc:
            print(f"Service call failed: {exc}", flush=True)
            ok = False
        if not ok:
            log.error("SetModelConfiguration service failed. Exiting.")
            return 1
    if args.unpause:
        log.info("Unpausing physics")
        try:
            call(node, f"{ns}/unpause_physics", Empty)
        except NinjemysError as exc:
            log.error("Unpause physics service call failed: %s", exc)
            return 1
    if args.bond:
        log.info("Waiting for shutdown to delete model %s", args.model)
        interrupted = threading.Event()
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, lambda *_: interrupted.set())
            signal.signal(signal.SIGTERM, lambda *_: interrupted.set())
        while not interrupted.wait(0.2) and not node.is_shutdown:
            pass
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    ros_args = [a for a in argv if ":=" in a]
    args = parser().parse_args([a for a in argv if ":=" not in a])  # exits 2 with argparse's usage line
    try:
        node = start_node(rospy_anonymous_name("spawn_model"), ros_args)
    except NinjemysError as exc:
        print(f"spawn_model: {exc}", file=sys.stderr)
        return 1
    try:
        code = run(node, args)
        if args.bond:
            node.log.info("Deleting model %s", args.model)
            try:
                call(
                    node,
                    f"{args.gazebo_namespace.rstrip('/')}/delete_model",
                    DeleteModel,
                    model_name=args.model,
                )
            except NinjemysError as exc:
                node.log.error("Delete model service call failed: %s", exc)
        return code
    except KeyboardInterrupt:
        return 1
    finally:
        node.shutdown("exit")


console_main = entry(main)
