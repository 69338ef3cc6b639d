"""``rosrun controller_manager spawner [options] controller ...``: load and start, unload on exit.

The command line, log lines and shutdown behaviour are controller_manager's spawner (Noetic): it
waits for ``<ns>/controller_manager/{load,switch,unload}_controller``, optionally for ``True`` on a
``--wait-for`` topic, loads each named controller (a name that is a YAML file is loaded onto the
parameter server first, its top-level keys taken as the controllers), starts them all in one strict
switch unless ``--stopped``, then spins; on Ctrl-C or ``rosnode kill`` it stops and unloads them.
"""

from __future__ import annotations

import argparse
import os
import threading
import time
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.node.run import run_node


def parse_args(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="spawner", description="Controller spawner")
    parser.add_argument("--stopped", action="store_true", help="loads controllers, but does not start them")
    parser.add_argument(
        "--wait-for",
        metavar="topic",
        help='does not load or start controllers until it hears "True" on a topic (Bool)',
    )
    parser.add_argument("--namespace", metavar="ns", help="namespace of the controller_manager services")
    parser.add_argument(
        "--timeout",
        metavar="T",
        type=float,
        default=30,
        help="how long to wait for controller_manager services when starting up [s] (default: 30). "
        "<=0 waits indefinitely.",
    )
    parser.add_argument(
        "--no-timeout", action="store_true", help="wait for controller_manager services indefinitely"
    )
    parser.add_argument("--shutdown-timeout", help="DEPRECATED: this argument has no effect.")
    parser.add_argument("controllers", metavar="controller", nargs="+", help="controllers to load")
    return parser.parse_args(argv)


def _user_args(argv: list[str]) -> list[str]:
    """rospy.myargv: the arguments without remappings (``a:=b``) and ``__name``-style specials."""
    return [a for a in argv if ":=" not in a]


def main(argv: list[str] | None = None) -> int:
    import sys

    raw = sys.argv[1:] if argv is None else argv
    args = parse_args(_user_args(raw))
    # anonymous, as spawner's rospy.init_node('spawner', anonymous=True)
    name = f"spawner_{os.uname().nodename.replace('-', '_')}_{os.getpid()}_{int(time.time() * 1000) % 10**9}"
    return run_node(name, [a for a in raw if ":=" in a], lambda node: _spawn(node, args))


def _spawn(node: Any, args: argparse.Namespace) -> int:
    log = node.log
    timeout = None if args.no_timeout or args.timeout <= 0 else args.timeout
    if args.shutdown_timeout is not None:
        log.warn("DEPRECATION warning: --shutdown-timeout has no effect.")
    ns = args.namespace or ""
    if ns and not ns.endswith("/"):
        ns += "/"
    load_name = ns + "controller_manager/load_controller"
    switch_name = ns + "controller_manager/switch_controller"
    unload_name = ns + "controller_manager/unload_controller"
    load_cls: Any = get_service_class("controller_manager_msgs/LoadController")
    switch_cls: Any = get_service_class("controller_manager_msgs/SwitchController")
    unload_cls: Any = get_service_class("controller_manager_msgs/UnloadController")
    while True:
        try:
            for service in (load_name, switch_name, unload_name):
                log.info(f"Controller Spawner: Waiting for service {service}")
                node.wait_for_service(service, timeout)
            break
        except NinjemysError:
            if node.is_shutdown:
                return 0
            use_sim = node.has_param("/use_sim_time") and node.get_param("/use_sim_time")
            if use_sim and node.get_time() == 0.0:
                log.info("Waiting for /clock to be available...")
                continue
            log.warn("Controller Spawner couldn't find the expected controller_manager ROS interface.")
            return 0
    load = node.service_proxy(load_name, load_cls)
    switch = node.service_proxy(switch_name, switch_cls)
    unload = node.service_proxy(unload_name, unload_cls)  # made now: shutdown hooks run on a closing node
    if args.wait_for and not _wait_for_true(node, args.wait_for, timeout):
        return 0
    loaded: list[str] = []

    def shutdown() -> None:
        log.info("Shutting down spawner. Stopping and unloading controllers...")
        try:
            log.info("Stopping all controllers...")
            switch(
                switch_cls._request_class(
                    stop_controllers=loaded, strictness=2, start_asap=False, timeout=0.0
                )
            )
            log.info("Unloading all loaded controllers...")
            for name in reversed(loaded):
                log.info(f"Trying to unload {name}")
                unload(unload_cls._request_class(name=name))
                log.info(f"Succeeded in unloading {name}")
        except NinjemysError as exc:
            log.warn(f"Controller Spawner error while taking down controllers: {exc}")

    node.on_shutdown(shutdown)
    controllers: list[str] = []
    for name in args.controllers:
        if os.path.exists(name):
            controllers.extend(_load_yaml(node, name))
        else:
            controllers.append(name)
    for name in controllers:
        log.info(f"Loading controller: {name}")
        resp = load(load_cls._request_class(name=name))
        if resp.ok:
            loaded.append(name)
        else:
            time.sleep(1)  # spawner gives the manager's error line a chance to get out first
            log.error(f"Failed to load {name}")
    log.info(f"Controller Spawner: Loaded controllers: {', '.join(loaded)}")
    if node.is_shutdown:
        return 0
    if not args.stopped:
        resp = switch(
            switch_cls._request_class(start_controllers=loaded, strictness=2, start_asap=False, timeout=0.0)
        )
        if resp.ok:
            log.info(f"Started controllers: {', '.join(loaded)}")
        else:
            log.error(f"Failed to start controllers: {', '.join(loaded)}")
    return 0


def _wait_for_true(node: Any, topic: str, timeout: float | None) -> bool:
    bool_cls: Any = get_message_class("std_msgs/Bool")
    heard = threading.Event()
    true = threading.Event()

    def on_msg(msg: Any) -> None:
        heard.set()
        if msg.data:
            true.set()

    sub = node.subscriber(topic, bool_cls, on_msg)
    try:
        if not heard.wait(timeout) and not node.is_shutdown:
            node.log.warn(f'Controller Spawner hasn\'t heard anything from its "wait for" topic ({topic})')
        while not true.wait(0.1):
            if node.is_shutdown:
                return False
        return True
    finally:
        sub.unregister()


def _load_yaml(node: Any, path: str) -> list[str]:
    """``rosparam load`` of the file into the root namespace; its top-level keys are controllers."""
    from ninjemys.paramyaml import load_yaml

    with open(path, encoding="utf-8") as f:
        doc = load_yaml(f.read())
    if not isinstance(doc, dict):
        return []
    for key, value in doc.items():
        node.set_param(key, value)
    return list(doc)


def unspawner_main(argv: list[str] | None = None) -> int:
    """``unspawner name ...``: stop the named controllers (again every 3 s) until killed, then restart them."""
    import sys

    raw = sys.argv[1:] if argv is None else argv
    names = [a for a in raw if ":=" not in a]
    if not names or names[0] in ("-h", "--help"):
        print("./unspawner name1 name2 name3\n\n\tStops a set of controllers until killed.")
        print("\tUseful in roslaunch files to temporarily stop controllers")
        return 1
    name = f"unspawner_{os.getpid()}_{int(time.time() * 1000) % 10**9}"
    return run_node(name, [a for a in raw if ":=" in a], lambda node: _unspawn(node, set(names)))


def _unspawn(node: Any, to_inhibit: set[str]) -> int:
    switch_cls: Any = get_service_class("controller_manager_msgs/SwitchController")
    list_cls: Any = get_service_class("controller_manager_msgs/ListControllers")
    node.wait_for_service("controller_manager/switch_controller")
    node.wait_for_service("controller_manager/list_controllers")
    switch = node.service_proxy("controller_manager/switch_controller", switch_cls)
    listing = node.service_proxy("controller_manager/list_controllers", list_cls)
    inhibited: set[str] = set()

    def stop(*_: Any) -> None:
        running = {c.name for c in listing(list_cls._request_class()).controller if c.state == "running"}
        to_stop = to_inhibit & running
        if to_stop:
            node.log.info(f"Inhibiting controllers: {', '.join(sorted(to_stop))}")
            switch(switch_cls._request_class(stop_controllers=sorted(to_stop), strictness=1))
            inhibited.update(to_stop)

    stop()
    timer = node.timer(3.0, stop)

    def restart() -> None:
        timer.shutdown()
        try:
            switch(switch_cls._request_class(start_controllers=sorted(inhibited), strictness=1))
        except NinjemysError as exc:
            node.log.warn(f"unspawner could not restart {sorted(inhibited)}: {exc}")

    node.on_shutdown(restart)
    return 0
