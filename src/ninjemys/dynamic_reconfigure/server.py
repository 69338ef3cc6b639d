"""The reconfigure server: holds a node's configuration and changes it on ``set_parameters`` calls.

ROS 1's protocol, under the namespace ``ns`` (``~`` by default):

* ``<ns>parameter_descriptions`` (ConfigDescription, latched): the groups, parameters, min/max/defaults;
* ``<ns>parameter_updates`` (Config, latched): the configuration after every change;
* ``<ns>set_parameters`` (Reconfigure): apply changes, answer with the resulting configuration.

Start-up reads each parameter from the parameter server (``<ns><name>``) over the defaults, clamps,
calls the callback with level ``~0`` and writes the result back to the parameter server, as ROS 1.
Values of the wrong type (from the parameter server or a client) are converted where ROS 1's types
allow it (an int for a double) and otherwise refused with one log line naming the parameter.
"""

from __future__ import annotations

import copy
import logging
import threading
from collections.abc import Callable, Mapping
from typing import Any

from ninjemys.dynamic_reconfigure.encoding import (
    PARAM_TYPES,
    Config,
    decode_config,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    initial_config,
)
from ninjemys.dynamic_reconfigure.errors import DynamicReconfigureCallbackException
from ninjemys.errors import MasterError, ParameterError
from ninjemys.idl.loader import get_message_class, get_service_class

_log = logging.getLogger(__name__)

Callback = Callable[[Config, int], Any]


def server_namespace(namespace: str) -> str:
    """ROS 1's rule: empty -> ``~``; relative names become private; always one trailing slash."""
    if not namespace:
        return "~"
    if namespace[0] not in "/~":
        namespace = "~" + namespace
    return (namespace + "/").replace("//", "/")


def coerce(param: Mapping[str, Any], value: Any) -> Any:
    """``value`` as the parameter's declared type, or raise ValueError saying why not."""
    want = PARAM_TYPES[param["type"]]
    if type(value) is want:
        return value
    if want is float and type(value) is int:
        return float(value)
    if want is int and type(value) is float and value.is_integer():
        return int(value)
    raise ValueError(f"parameter '{param['name']}' is {param['type']}, got {value!r}")


def clamp(config_type: Any, config: dict[str, Any]) -> None:
    """Bring numeric values inside their declared [min, max] (strings and bools are left alone)."""
    for param in extract_params(config_type.config_description):
        if param["type"] not in ("int", "double"):
            continue
        name = param["name"]
        value = config[name]
        if value > config_type.max[name]:
            config[name] = config_type.max[name]
        elif value < config_type.min[name]:
            config[name] = config_type.min[name]


class ReconfigureServer:
    """A dynamic_reconfigure server on ``node`` for a generated ``<Name>Config`` module.

    ``callback(config, level)`` gets the proposed configuration and the OR of the levels of the
    parameters that changed; what it returns becomes the configuration.
    """

    def __init__(self, node: Any, config_type: Any, callback: Callback, namespace: str = "") -> None:
        self.node = node
        self.type = config_type
        self.ns = server_namespace(namespace)
        self.callback = callback
        self.mutex = threading.Lock()
        self._params = extract_params(config_type.config_description)
        self.description = encode_description(config_type)
        config = Config(config_type.defaults)
        self._read_parameter_server(config)
        clamp(config_type, config)
        config["groups"] = get_tree(self.description)
        self.config: Config = initial_config(encode_config(config), config_type.config_description)
        self.descr_topic = node.publisher(
            self.ns + "parameter_descriptions",
            get_message_class("dynamic_reconfigure/ConfigDescription"),
            queue_size=10,
            latch=True,
        )
        self.descr_topic.publish(self.description)
        self.update_topic = node.publisher(
            self.ns + "parameter_updates",
            get_message_class("dynamic_reconfigure/Config"),
            queue_size=10,
            latch=True,
        )
        with self.mutex:
            self._change(self.config, ~0)
        service = get_service_class("dynamic_reconfigure/Reconfigure")
        self._response = service._response_class
        self.set_service = node.service(self.ns + "set_parameters", service, self._on_set)

    def _read_parameter_server(self, config: Config) -> None:
        for param in self._params:
            key = self.ns + param["name"]
            try:
                value = self.node.get_param(key)
            except ParameterError:
                continue
            except MasterError as exc:
                _log.warning("dynamic_reconfigure: cannot read parameter %s: %s", key, exc)
                continue
            try:
                config[param["name"]] = coerce(param, value)
            except ValueError as exc:
                _log.warning(
                    "dynamic_reconfigure: %s: %s; using %r",
                    self.node.resolve_name(key),
                    exc,
                    config[param["name"]],
                )

    def _write_parameter_server(self) -> None:
        for param in self._params:
            try:
                self.node.set_param(self.ns + param["name"], self.config[param["name"]])
            except MasterError as exc:
                _log.warning("dynamic_reconfigure: cannot write parameter %s: %s", param["name"], exc)

    def _change(self, config: Config, level: int) -> Config:
        result = self.callback(config, level)
        if result is None:
            msg = "Reconfigure callback should return a possibly updated configuration."
            _log.error(msg)
            raise DynamicReconfigureCallbackException(msg)
        self.config = result
        self._write_parameter_server()
        self.update_topic.publish(encode_config(self.config))
        return self.config

    def _level(self, new: Mapping[str, Any], old: Mapping[str, Any]) -> int:
        level = 0
        for param in self._params:
            if new[param["name"]] != old[param["name"]]:
                level |= param["level"]
        return level

    def update_configuration(self, changes: Mapping[str, Any]) -> Config:
        """Apply ``changes`` (name -> value, optionally ``groups``), run the callback, publish the result."""
        known = {p["name"]: p for p in self._params}
        with self.mutex:
            new = copy.deepcopy(self.config)
            for name, value in changes.items():
                if name == "groups":
                    new[name] = value
                elif name not in known:
                    _log.warning("dynamic_reconfigure %s: ignoring unknown parameter '%s'", self.ns, name)
                else:
                    try:
                        new[name] = coerce(known[name], value)
                    except ValueError as exc:
                        _log.warning("dynamic_reconfigure %s: %s; keeping %r", self.ns, exc, new[name])
            clamp(self.type, new)
            return self._change(new, self._level(new, self.config))

    def _on_set(self, request: Any) -> Any:
        changes = decode_config(request.config, self.type.config_description)
        return self._response(encode_config(self.update_configuration(changes)))

    def shutdown(self) -> None:
        """Stop serving: the service and both topics go away."""
        self.set_service.shutdown()
        self.descr_topic.unregister()
        self.update_topic.unregister()
