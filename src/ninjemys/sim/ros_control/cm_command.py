"""``rosrun controller_manager controller_manager <command> [name ...]``, with controller_manager's texts.

Commands: load, unload, start, stop, spawn (sp), kill (kl), list (lc), list-types (lt),
reload-libraries [--restore]; the services are ``controller_manager/...`` relative to the node's
namespace (``__ns:=``/ROS_NAMESPACE), as the original script resolves them.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_service_class
from ninjemys.node.run import start_node

USAGE = """Commands:
    load <name>          - Load the controller named <name>
    unload <name>        - Unload the controller named <name>
    start <name>         - Start the controller named <name>
    stop <name>          - Stop the controller named <name>
    spawn <name>         - Load and start the controller named <name>
    kill <name>          - Stop and unload the controller named <name>
    list                 - List active controllers
    list-types           - List controller Types
    reload-libraries     - Reloads all plugin controller libraries"""

STRICT, BEST_EFFORT = 2, 1


class _Client:
    def __init__(self, node: Any) -> None:
        self.node = node

    def call(self, service: str, kind: str, **fields: Any) -> Any:
        name = f"controller_manager/{service}"
        self.node.wait_for_service(name)
        cls: Any = get_service_class(f"controller_manager_msgs/{kind}")
        return self.node.service_proxy(name, cls)(cls._request_class(**fields))

    def load(self, name: str) -> bool:
        ok = self.call("load_controller", "LoadController", name=name).ok
        print(f"Loaded '{name}'" if ok else f"Error when loading '{name}'")
        return ok

    def unload(self, name: str) -> bool:
        ok = self.call("unload_controller", "UnloadController", name=name).ok
        print(f"Unloaded '{name}' successfully" if ok else f"Error when unloading '{name}'")
        return ok

    def switch(self, start: list[str], stop: list[str], strictness: int = STRICT) -> bool:
        ok = self.call(
            "switch_controller",
            "SwitchController",
            start_controllers=start,
            stop_controllers=stop,
            strictness=strictness,
            start_asap=False,
            timeout=0.0,
        ).ok
        if ok:
            if start:
                print(f"Started {start} successfully")
            if stop:
                print(f"Stopped {stop} successfully")
        else:
            print(f"Error when starting {start} and stopping {stop}")
        return ok

    def list(self) -> None:
        resp = self.call("list_controllers", "ListControllers")
        if not resp.controller:
            print("No controllers are loaded in mechanism control")
        for c in resp.controller:
            hwi = sorted({r.hardware_interface for r in c.claimed_resources})
            print(f"'{c.name}' - '{'+'.join(hwi)}' ( {c.state} )")

    def list_types(self) -> None:
        resp = self.call("list_controller_types", "ListControllerTypes")
        for t in resp.types:
            print(t)

    def reload(self, restore: bool) -> None:
        before = self.call("list_controllers", "ListControllers").controller
        if restore:
            running = [c.name for c in before if c.state == "running"]
            if running:
                self.switch([], running, BEST_EFFORT)
            for c in before:
                self.unload(c.name)
        if self.call("reload_controller_libraries", "ReloadControllerLibraries", force_kill=True).ok:
            print("Successfully reloaded libraries")
        else:
            print("Failed to reload libraries. Do you still have controllers loaded?")
        if restore:
            for c in before:
                self.load(c.name)
            self.switch([c.name for c in before if c.state == "running"], [], BEST_EFFORT)
            print("Controllers restored to original state")


def main(argv: list[str] | None = None) -> int:
    raw = sys.argv[1:] if argv is None else argv
    args = [a for a in raw if ":=" not in a]
    if not args:
        print(USAGE)
        return 0
    command, names = args[0], args[1:]
    known = {
        "lt",
        "list-types",
        "lc",
        "list",
        "reload-libraries",
        "load",
        "unload",
        "start",
        "stop",
        "sp",
        "spawn",
        "kl",
        "kill",
    }
    if command not in known:
        print(USAGE)
        return 1
    node = start_node(
        f"controller_manager_{os.getpid()}_{int(time.time() * 1000) % 10**9}", [a for a in raw if ":=" in a]
    )
    try:
        c = _Client(node)
        if command in ("lt", "list-types"):
            c.list_types()
        elif command in ("lc", "list"):
            c.list()
        elif command == "reload-libraries":
            c.reload("--restore" in names)
        elif command == "load":
            for n in names:
                c.load(n)
        elif command == "unload":
            for n in names:
                c.unload(n)
        elif command == "start":
            for n in names:
                c.switch([n], [])
        elif command == "stop":
            for n in names:
                c.switch([], [n])
        elif command in ("sp", "spawn"):
            for n in names:
                c.load(n)
            for n in names:
                c.switch([n], [])
        else:
            for n in names:
                c.switch([], [n])
            for n in names:
                c.unload(n)
    except NinjemysError as exc:
        print(f"controller_manager: {exc}", file=sys.stderr)
        return 1
    finally:
        node.shutdown("done")
    return 0
