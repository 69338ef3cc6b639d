"""The reconfigure client: follows a server's configuration and asks it for changes.

It waits for ``<name>/set_parameters`` (saying so on stderr after a second, as ROS 1), subscribes
``<name>/parameter_descriptions`` and ``<name>/parameter_updates`` (both latched, so the current state
arrives at once), and converts the values of ``update_configuration`` to the parameters' types
(``"true"`` for a bool, an enum constant's name for an enum parameter) before sending them.
"""

from __future__ import annotations

import ast
import sys
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from ninjemys.dynamic_reconfigure.encoding import (
    PARAM_TYPES,
    Config,
    decode_config,
    decode_description,
    encode_config,
    extract_params,
)
from ninjemys.dynamic_reconfigure.errors import (
    DynamicReconfigureCallbackException,
    DynamicReconfigureParameterException,
)
from ninjemys.errors import ServiceError, TimeoutError_
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.interrupt import wait_slice
from ninjemys.master.snapshot import GraphSnapshot


def reconfigure_servers(node: Any) -> list[str]:
    """Every node name that offers ``<name>/set_parameters``, sorted (``dynparam list``)."""
    suffix = "/set_parameters"
    services = GraphSnapshot.fetch(node.master, with_types=False).services
    return sorted(name[: -len(suffix)] for name in services if name.endswith(suffix))


def _param_type(name: str) -> type:
    try:
        return PARAM_TYPES[name]
    except KeyError:
        raise DynamicReconfigureParameterException(
            f"parameter has unknown type: {name}. This is a bug in dynamic_reconfigure."
        ) from None


class ReconfigureClient:
    """Client of the dynamic_reconfigure server ``name`` (usually a node name)."""

    def __init__(
        self,
        node: Any,
        name: str,
        timeout: float | None = None,
        config_callback: Callable[[Config | None], Any] | None = None,
        description_callback: Callable[[list[dict[str, Any]] | None], Any] | None = None,
    ) -> None:
        self.node = node
        self.name = name
        self.config: Config | None = None
        self.param_description: list[dict[str, Any]] | None = None
        self.group_description: Config | None = None
        self._param_types: dict[str, type] = {}
        self._cv = threading.Condition()
        self._closed = False
        self._config_callback = config_callback
        self._description_callback = description_callback
        node.on_shutdown(self._wake)
        service = node.resolve_name(name + "/set_parameters")
        if timeout is None or timeout == 0.0:
            try:
                node.wait_for_service(service, 1.0)
            except TimeoutError_:
                print(f"Waiting for service {service}...", file=sys.stderr)
                node.wait_for_service(service, None)
        else:
            node.wait_for_service(service, timeout)
        self._set_service = node.service_proxy(service, get_service_class("dynamic_reconfigure/Reconfigure"))
        self._descriptions_sub = node.subscriber(
            node.resolve_name(name + "/parameter_descriptions"),
            get_message_class("dynamic_reconfigure/ConfigDescription"),
            self._on_descriptions,
        )
        self._updates_sub = node.subscriber(
            node.resolve_name(name + "/parameter_updates"),
            get_message_class("dynamic_reconfigure/Config"),
            self._on_update,
        )

    def _wake(self) -> None:
        with self._cv:
            self._closed = True
            self._cv.notify_all()

    def _wait_for(self, attr: str, timeout: float | None) -> Any:
        deadline = None if timeout is None or timeout == 0.0 else time.monotonic() + timeout
        with self._cv:
            while getattr(self, attr) is None and not self._closed and not self.node.is_shutdown:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0.0:
                    break
                self._cv.wait(wait_slice(left))
            return getattr(self, attr)

    def get_configuration(self, timeout: float | None = None) -> Config | None:
        """The server's latest configuration; waits for the first one (None after ``timeout``)."""
        if timeout is None or timeout == 0.0:
            if self._wait_for("config", 1.0) is None and not self.node.is_shutdown:
                print("Waiting for configuration...", file=sys.stderr)
                return self._wait_for("config", None)
            return self.config
        return self._wait_for("config", timeout)

    def get_parameter_descriptions(self, timeout: float | None = None) -> list[dict[str, Any]] | None:
        """Each parameter's name, type, level, description, edit_method, min, max and default."""
        return self._wait_for("param_description", timeout)

    def get_group_descriptions(self, timeout: float | None = None) -> Config | None:
        """The group tree (``groups`` keyed by name) with each group's parameter descriptions."""
        return self._wait_for("group_description", timeout)

    def _convert(self, name: str, value: Any) -> Any:
        dest = self._param_types.get(name)
        if dest is None:
            raise DynamicReconfigureParameterException(f"don't know parameter: {name}")
        descr = next(p for p in self.param_description or [] if p["name"].lower() == name.lower())
        try:
            if dest is bool and type(value) is str:
                return value.lower() in ("yes", "true", "t", "1")
            if type(value) is str and descr["edit_method"]:
                for const in ast.literal_eval(descr["edit_method"])["enum"]:
                    if value.lower() == const["name"].lower():
                        return _param_type(const["type"])(const["value"])
            return dest(value)
        except ValueError as exc:
            raise DynamicReconfigureParameterException(
                f"can't set parameter '{name}' of {dest!s}: {exc}"
            ) from None

    def update_configuration(self, changes: dict[str, Any]) -> Config:
        """Ask the server to apply ``changes``; returns the configuration it ended up with."""
        if self.param_description is None:
            self.get_parameter_descriptions()
        if self.param_description is not None:
            for name, value in list(changes.items()):
                if name != "groups":
                    changes[name] = self._convert(name, value)
        if "groups" in changes:
            changes["groups"] = self.update_groups(changes["groups"])
        try:
            reply = self._set_service(encode_config(changes)).config
        except ServiceError:
            raise DynamicReconfigureCallbackException("service call failed") from None
        if self.group_description is None:
            self.get_group_descriptions()
        return decode_config(reply, self.group_description)

    def update_groups(self, changes: Mapping[str, bool]) -> Config | None:
        """The group tree with the states of the named groups set (``{"Limits": False}``)."""
        descr = self.get_group_descriptions()

        def set_state(group: str, tree: Mapping[str, Any]) -> None:
            for child in tree["groups"].values():
                if child["name"] == group:
                    child["state"] = changes[group]
                else:
                    set_state(group, child)

        if descr is not None:
            for group in changes:
                set_state(group, descr)
        return descr

    def close(self) -> None:
        """Stop following the server."""
        self._descriptions_sub.unregister()
        self._updates_sub.unregister()
        self._set_service.close()

    def get_config_callback(self) -> Callable[[Config | None], Any] | None:
        return self._config_callback

    def set_config_callback(self, value: Callable[[Config | None], Any] | None) -> None:
        """Set the callback for new configurations; it runs at once with the current one, as in ROS 1."""
        self._config_callback = value
        if value is not None:
            value(self.config)

    config_callback = property(get_config_callback, set_config_callback)

    def get_description_callback(self) -> Callable[[list[dict[str, Any]] | None], Any] | None:
        return self._description_callback

    def set_description_callback(self, value: Callable[[list[dict[str, Any]] | None], Any] | None) -> None:
        """Set the callback for new descriptions; it runs at once with the current one, as in ROS 1."""
        self._description_callback = value
        if value is not None:
            value(self.param_description)

    description_callback = property(get_description_callback, set_description_callback)

    def _on_update(self, msg: Any) -> None:
        if self.group_description is None:
            self.get_group_descriptions()
        config = decode_config(msg, self.group_description)
        with self._cv:
            self.config = config
            self._cv.notify_all()
        if self._config_callback is not None:
            self._config_callback(config)

    def _on_descriptions(self, msg: Any) -> None:
        groups = decode_description(msg)
        params = extract_params(groups) if groups else []
        types = {p["name"]: _param_type(p["type"]) for p in params}
        with self._cv:
            self.group_description = groups
            self.param_description = params
            self._param_types = types
            self._cv.notify_all()
        if self._description_callback is not None:
            self._description_callback(params)
