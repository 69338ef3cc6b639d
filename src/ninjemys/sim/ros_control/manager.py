"""controller_manager: load, unload, switch and list controllers, with ROS 1's service names and texts.

The services live under ``<ns>/controller_manager/`` (gazebo_ros_control's robotNamespace) and a
controller's parameters under ``<ns>/<name>``, its type in ``<ns>/<name>/type``. A switch is applied
at once under the manager's lock, so the next :meth:`ControllerManager.update` runs the new set;
refusals (unknown type, resource conflict, unloading a running controller) log ROS 1's error line and
answer ``ok: False``, as controller_manager does.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.sim.ros_control.controllers import CONTROLLER_TYPES as DRIVE_TYPES
from ninjemys.sim.ros_control.controllers import Controller, ControllerError
from ninjemys.sim.ros_control.hardware import SimRobotHW
from ninjemys.sim.ros_control.joint_controllers import JOINT_CONTROLLER_TYPES

BEST_EFFORT, STRICT = 1, 2
#: every controller type the simulator's controller_manager loads
CONTROLLER_TYPES = {**DRIVE_TYPES, **JOINT_CONTROLLER_TYPES}
BASE_CLASS = "controller_interface::ControllerBase"


@dataclass
class Loaded:
    controller: Controller
    state: str = "initialized"  # then "running" / "stopped", as controller_manager reports
    pending_start: bool = False


def _join(ns: str, name: str) -> str:
    return f"{ns.rstrip('/')}/{name}"


class ControllerManager:
    def __init__(self, node: Any, hw: SimRobotHW, namespace: str = "/") -> None:
        self.node, self.hw = node, hw
        self.ns = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self.controllers: dict[str, Loaded] = {}
        self._lock = threading.RLock()
        self.now = 0.0
        base = _join(self.ns, "controller_manager")
        srv: dict[str, Any] = {
            n: get_service_class(f"controller_manager_msgs/{n}")
            for n in (
                "LoadController",
                "UnloadController",
                "SwitchController",
                "ListControllers",
                "ListControllerTypes",
                "ReloadControllerLibraries",
            )
        }
        self._state_msg: Any = get_message_class("controller_manager_msgs/ControllerState")
        self._res_msg: Any = get_message_class("controller_manager_msgs/HardwareInterfaceResources")
        self._srv_classes: dict[str, Any] = srv
        self.services = [
            node.service(_join(base, "load_controller"), srv["LoadController"], self._on_load),
            node.service(_join(base, "unload_controller"), srv["UnloadController"], self._on_unload),
            node.service(_join(base, "switch_controller"), srv["SwitchController"], self._on_switch),
            node.service(_join(base, "list_controllers"), srv["ListControllers"], self._on_list),
            node.service(_join(base, "list_controller_types"), srv["ListControllerTypes"], self._on_types),
            node.service(
                _join(base, "reload_controller_libraries"), srv["ReloadControllerLibraries"], self._on_reload
            ),
        ]

    # -- the API (also used directly by tests and by the simulator) --

    def load(self, name: str) -> bool:
        log = self.node.log
        with self._lock:
            if name in self.controllers:
                log.error(f"A controller named '{name}' was already loaded inside the controller manager")
                return False
            key = _join(self.ns, name)
            try:
                params = self.node.get_param(key)
            except NinjemysError:
                params = None
            if not isinstance(params, dict) or "type" not in params:
                log.error(
                    f"Could not load controller '{name}' because the type was not specified. Did you load"
                    f" the controller configuration on the parameter server (namespace: '{key}')?"
                )
                return False
            kind = params["type"]
            cls = CONTROLLER_TYPES.get(kind) if isinstance(kind, str) else None
            if cls is None:
                log.error(
                    f"Could not load controller '{name}' because controller type '{kind}' does not exist."
                )
                log.error(
                    "Use 'rosservice call controller_manager/list_controller_types' to get the available types"
                )
                return False
            try:
                controller = cls(name, self.node, self.hw, self.ns or "/", params)
            except ControllerError as exc:
                log.error(str(exc))
                log.error(f"Initializing controller '{name}' failed")
                return False
            self.controllers[name] = Loaded(controller)
            return True

    def unload(self, name: str) -> bool:
        log = self.node.log
        with self._lock:
            entry = self.controllers.get(name)
            if entry is None:
                log.error(
                    f"Could not unload controller with name '{name}' because no controller with this name exists"
                )
                return False
            if entry.state == "running":
                log.error(f"Could not unload controller with name '{name}' because it is still running")
                return False
            del self.controllers[name]
        entry.controller.close()
        return True

    def switch(self, start: list[str], stop: list[str], strictness: int = STRICT) -> bool:
        log = self.node.log
        if strictness not in (BEST_EFFORT, STRICT):
            strictness = BEST_EFFORT  # controller_manager treats 0 as BEST_EFFORT
        with self._lock:
            start_ok, stop_ok = [], []
            for name in stop:
                entry = self.controllers.get(name)
                if entry is None:
                    log.error(
                        f"Could not stop controller with name '{name}' because no controller with this name exists"
                    )
                    if strictness == STRICT:
                        return False
                elif entry.state != "running" and strictness == STRICT:
                    log.error(f"Could not stop controller with name '{name}' because it is not running")
                    return False
                elif entry.state == "running":
                    stop_ok.append(name)
            for name in start:
                entry = self.controllers.get(name)
                if entry is None:
                    log.error(
                        f"Could not start controller with name '{name}' because no controller with this name exists"
                    )
                    if strictness == STRICT:
                        return False
                elif entry.state == "running" and name not in stop_ok:
                    if strictness == STRICT:
                        log.error(
                            f"Could not start controller with name '{name}' because it is already running"
                        )
                        return False
                else:
                    start_ok.append(name)
            # resources: every joint claimed by at most one running controller after the switch
            owners: dict[str, str] = {}
            after = [
                n for n, e in self.controllers.items() if e.state == "running" and n not in stop_ok
            ] + start_ok
            for name in after:
                for joint in self.controllers[name].controller.claimed:
                    if joint in owners:
                        log.error(
                            f"Resource conflict on [{joint}].  Controllers = [{owners[joint]}, {name}, ]"
                        )
                        log.error("Could not switch controllers, due to resource conflict")
                        return False
                    owners[joint] = name
            for name in stop_ok:
                self.controllers[name].controller.stopping(self.now)
                self.controllers[name].state = "stopped"
            for name in start_ok:
                self.controllers[name].controller.starting(self.now)
                self.controllers[name].state = "running"
            return True

    def update(self, now: float, period: float) -> dict[str, float]:
        """Run every running controller once; the joint velocity commands of the claimed joints."""
        with self._lock:
            self.now = now
            claimed: list[str] = []
            for entry in self.controllers.values():
                if entry.state == "running":
                    entry.controller.update(now, period)
                    claimed.extend(entry.controller.claimed)
            return self.hw.commands(claimed)

    def close(self) -> None:
        with self._lock:
            entries = list(self.controllers.values())
            self.controllers.clear()
        for e in entries:
            e.controller.close()
        for s in self.services:
            try:
                self.node.release_service(s)
            except NinjemysError:
                pass

    # -- services --

    def _on_load(self, req: Any) -> Any:
        return self._srv_classes["LoadController"]._response_class(ok=self.load(req.name))

    def _on_unload(self, req: Any) -> Any:
        return self._srv_classes["UnloadController"]._response_class(ok=self.unload(req.name))

    def _on_switch(self, req: Any) -> Any:
        ok = self.switch(list(req.start_controllers), list(req.stop_controllers), req.strictness)
        return self._srv_classes["SwitchController"]._response_class(ok=ok)

    def _on_list(self, _req: Any) -> Any:
        with self._lock:
            states = [
                self._state_msg(
                    name=name,
                    state=e.state,
                    type=e.controller.type_name,
                    claimed_resources=[
                        self._res_msg(
                            hardware_interface=e.controller.interface, resources=e.controller.claimed
                        )
                    ],
                )
                for name, e in self.controllers.items()
            ]
        return self._srv_classes["ListControllers"]._response_class(controller=states)

    def _on_types(self, _req: Any) -> Any:
        types = sorted(CONTROLLER_TYPES)
        return self._srv_classes["ListControllerTypes"]._response_class(
            types=types, base_classes=[BASE_CLASS] * len(types)
        )

    def _on_reload(self, req: Any) -> Any:
        with self._lock:
            running = [n for n, e in self.controllers.items() if e.state == "running"]
            if self.controllers and not req.force_kill:
                self.node.log.error(
                    "Controller manager: Cannot reload controller libraries because there are still "
                    f"{len(self.controllers)} controllers loaded"
                )
                return self._srv_classes["ReloadControllerLibraries"]._response_class(ok=False)
        if running:
            self.switch([], running, BEST_EFFORT)
        for name in list(self.controllers):
            self.unload(name)
        return self._srv_classes["ReloadControllerLibraries"]._response_class(ok=True)
