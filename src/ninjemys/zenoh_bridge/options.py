"""The command line of ``zenoh-bridge-ros1``, with the Rust bridge's option names and defaults.

Everything is checked here, before anything starts, so a bad value gives one line naming the
option: an endpoint without ``proto/address``, a bridging mode that does not exist, a custom-mode
map that is not a JSON object of topic -> mode, a polling interval that is not ``[0-9]+(ns|us|ms|s|m|h)``.
"""

from __future__ import annotations

import argparse
import json
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ninjemys.errors import NinjemysError

AUTO, LAZY_AUTO, DISABLED = "auto", "lazy_auto", "disabled"
MODES = (AUTO, LAZY_AUTO, DISABLED)
#: client bridging has no lazy form: ROS 1 cannot say who is a client of a service
CLIENT_MODES = (AUTO, DISABLED)
KINDS = ("subscriber", "publisher", "service", "client")

_ENDPOINT = re.compile(r"^[a-z][a-z0-9-]*/\S+$")
_PROTOCOLS = ("tcp", "udp", "tls", "quic", "ws", "unixsock-stream", "unixpipe", "serial", "vsock")
_DURATION = re.compile(r"^(\d+)(ns|us|ms|s|m|h|d|w|y)$")
_UNIT_S = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0, "m": 60.0, "h": 3600.0, "d": 86400.0}
_UNIT_S.update(w=7 * 86400.0, y=365 * 86400.0)


class OptionsError(NinjemysError, ValueError):
    """A command-line value the bridge cannot use; the message names the option."""


@dataclass
class BridgeOptions:
    """Everything the bridge runs with (defaults are the Rust bridge's)."""

    mode: str = "peer"
    zenoh_id: str | None = None
    config_file: str | None = None
    listen: list[str] = field(default_factory=list)
    connect: list[str] = field(default_factory=list)
    multicast_scouting: bool = True
    ros_master_uri: str = "http://localhost:11311/"
    ros_hostname: str | None = None
    ros_name: str = "ros1_to_zenoh_bridge"
    ros_namespace: str = "/"
    bridge_namespace: str = "*"
    with_rosmaster: bool = False
    modes: dict[str, str] = field(
        default_factory=lambda: {"subscriber": AUTO, "publisher": AUTO, "service": AUTO, "client": DISABLED}
    )
    custom_modes: dict[str, dict[str, str]] = field(default_factory=lambda: {k: {} for k in KINDS})
    polling_interval: float = 0.1

    def mode_for(self, kind: str, topic: str) -> str:
        """The bridging mode of ``topic`` for ``kind``: its custom entry, else the global one."""
        return self.custom_modes[kind].get(topic, self.modes[kind])

    def node_name(self) -> str:
        """The bridge node's global name (what it signs as with per-node keys)."""
        if self.ros_name.startswith("/"):
            return self.ros_name
        return self.ros_namespace.rstrip("/") + "/" + self.ros_name

    def zenoh_config_json(self) -> dict[str, Any]:
        """The settings this command line puts over the Zenoh configuration (key -> JSON value)."""
        out: dict[str, Any] = {"mode": self.mode}
        if self.zenoh_id:
            out["id"] = self.zenoh_id
        if self.listen:
            out["listen/endpoints"] = self.listen
        if self.connect:
            out["connect/endpoints"] = self.connect
        if not self.multicast_scouting:
            out["scouting/multicast/enabled"] = False
        return out


def build_parser() -> argparse.ArgumentParser:
    """The parser, with the Rust bridge's option names (help texts are ours)."""
    p = argparse.ArgumentParser(
        prog="zenoh-bridge-ros1",
        description="Bridge a ROS 1 graph (its master's topics and services) to Zenoh and back.",
    )
    z = p.add_argument_group("zenoh")
    z.add_argument(
        "-i", "--id", dest="zenoh_id", metavar="HEX_STRING", help="this session's Zenoh id (hex, <= 32 chars)"
    )
    z.add_argument(
        "-m", "--mode", choices=("peer", "client"), default="peer", help="Zenoh session mode (default peer)"
    )
    z.add_argument(
        "-c", "--config", dest="config_file", metavar="FILE", help="a Zenoh JSON5 configuration file"
    )
    z.add_argument(
        "-l",
        "--listen",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="listen on ENDPOINT (repeatable), e.g. tcp/0.0.0.0:7447",
    )
    z.add_argument(
        "-e",
        "--connect",
        action="append",
        default=[],
        metavar="ENDPOINT",
        help="connect to ENDPOINT (repeatable)",
    )
    z.add_argument(
        "--no-multicast-scouting", action="store_true", help="neither send nor answer UDP multicast scouting"
    )
    z.add_argument(
        "--rest-http-port", metavar="PORT", help="refused: the REST plugin is not in the Python Zenoh package"
    )
    r = p.add_argument_group("ros1")
    r.add_argument(
        "--ros_master_uri",
        metavar="URI",
        help="the ROS master (default $ROS_MASTER_URI or http://localhost:11311/)",
    )
    r.add_argument(
        "--ros_hostname", metavar="NAME", help="the host name advertised to ROS nodes (as ROS_HOSTNAME)"
    )
    r.add_argument(
        "--ros_name",
        default=None,
        metavar="NAME",
        help='the bridge node\'s name (default "ros1_to_zenoh_bridge")',
    )
    r.add_argument(
        "--ros_namespace", default=None, metavar="NS", help="the bridge node's ROS namespace (default /)"
    )
    r.add_argument(
        "--bridge_namespace",
        default=None,
        metavar="NS",
        help='the per-robot Zenoh key prefix (default "*": every namespace)',
    )
    r.add_argument(
        "--with_rosmaster",
        default="false",
        metavar="BOOL",
        help="start a ROS master in the bridge (true/false)",
    )
    for kind in KINDS:
        modes = CLIENT_MODES if kind == "client" else MODES
        default = DISABLED if kind == "client" else AUTO
        r.add_argument(
            f"--{kind}_bridging_mode",
            default=None,
            metavar="MODE",
            help=f"{'/'.join(modes)} (default {default})",
        )
        r.add_argument(
            f"--{kind}_topic_custom_bridging_mode",
            default=None,
            metavar="JSON",
            help='per-topic modes: {"/topic": "mode"}',
        )
    r.add_argument(
        "--ros_master_polling_interval",
        default=None,
        metavar="DURATION",
        help="how often the master is read (default 100ms)",
    )
    r.add_argument(
        "--work_thread_num", type=int, default=None, help="accepted for compatibility (Rust runtime threads)"
    )
    r.add_argument(
        "--max_block_thread_num",
        type=int,
        default=None,
        help="accepted for compatibility (Rust runtime threads)",
    )
    return p


def parse_duration(text: str, option: str) -> float:
    """Seconds in ``text`` (``100ms``, ``2s``, ``5m``)."""
    m = _DURATION.match(text.strip())
    if m is None:
        raise OptionsError(f"{option}: {text!r} is not a duration such as 100ms, 2s or 5m")
    return int(m.group(1)) * _UNIT_S[m.group(2)]


def check_endpoint(endpoint: str, option: str) -> str:
    """``endpoint`` if it reads ``proto/address`` with a protocol Zenoh has."""
    if not _ENDPOINT.match(endpoint) or endpoint.split("/", 1)[0] not in _PROTOCOLS:
        raise OptionsError(
            f"{option}: bad endpoint {endpoint!r}: expected <protocol>/<address>, e.g. tcp/127.0.0.1:7447 "
            f"(protocols: {', '.join(_PROTOCOLS)})"
        )
    if endpoint.startswith(("tcp/", "udp/", "tls/", "quic/")):
        address = endpoint.split("/", 1)[1].split("#", 1)[0]
        host, sep, port = address.rpartition(":")
        if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
            raise OptionsError(f"{option}: bad endpoint {endpoint!r}: expected host:port after the protocol")
    return endpoint


def _mode(value: str, option: str, allowed: Sequence[str]) -> str:
    if value not in allowed:
        raise OptionsError(f"{option}: unknown bridging mode {value!r} (accepted: {', '.join(allowed)})")
    return value


def _custom(text: str, option: str, allowed: Sequence[str]) -> dict[str, str]:
    try:
        value = json.loads(text)
    except ValueError as exc:
        raise OptionsError(f"{option}: not JSON: {exc}") from None
    if not isinstance(value, dict):
        raise OptionsError(
            f'{option}: expected a JSON object {{"/topic": "mode"}}, got {type(value).__name__}'
        )
    out = {}
    for topic, mode in value.items():
        if not isinstance(mode, str):
            raise OptionsError(f"{option}: topic {topic!r}: mode must be a string")
        out["/" + topic.strip("/")] = _mode(mode, f"{option} (topic {topic})", allowed)
    return out


def _bool(text: str, option: str) -> bool:
    low = text.strip().lower()
    if low not in ("true", "false"):
        raise OptionsError(f"{option}: expected true or false, not {text!r}")
    return low == "true"


def parse_options(argv: Sequence[str] | None = None, env: Mapping[str, str] | None = None) -> BridgeOptions:
    """Parse and check the command line; the environment fills what the Rust bridge reads from it."""
    env = os.environ if env is None else env
    a = build_parser().parse_args(argv)
    if a.rest_http_port is not None:
        raise OptionsError(
            "--rest-http-port: the REST plugin is not part of the Python Zenoh package; not supported"
        )
    o = BridgeOptions(mode=a.mode, zenoh_id=a.zenoh_id, config_file=a.config_file)
    if a.zenoh_id is not None and (not re.fullmatch(r"[0-9a-fA-F]{1,32}", a.zenoh_id)):
        raise OptionsError(f"--id: {a.zenoh_id!r} is not a hexadecimal string of at most 32 characters")
    if a.config_file is not None and not os.path.isfile(a.config_file):
        raise OptionsError(f"--config: no such file {a.config_file!r}")
    o.listen = [check_endpoint(e, "--listen") for e in a.listen]
    o.connect = [check_endpoint(e, "--connect") for e in a.connect]
    o.multicast_scouting = not a.no_multicast_scouting
    o.ros_master_uri = a.ros_master_uri or env.get("ROS_MASTER_URI") or o.ros_master_uri
    if not re.match(r"^https?://[^/:]+:\d+/?$", o.ros_master_uri):
        raise OptionsError(f"--ros_master_uri: {o.ros_master_uri!r} is not http://host:port/")
    o.ros_hostname = a.ros_hostname
    o.ros_name = a.ros_name or env.get("ROS_NAME") or o.ros_name
    o.ros_namespace = a.ros_namespace or env.get("ROS_NAMESPACE") or "/"
    ns = a.bridge_namespace or env.get("BRIDGE_NAMESPACE") or "*"
    if ns != "*" and not re.fullmatch(r"[A-Za-z0-9_.~+-]+", ns):
        raise OptionsError(
            f"--bridge_namespace: {ns!r} must be one key chunk (letters, digits, _ . ~ + -) or *"
        )
    o.bridge_namespace = ns
    o.with_rosmaster = _bool(a.with_rosmaster, "--with_rosmaster")
    for kind in KINDS:
        allowed = CLIENT_MODES if kind == "client" else MODES
        value = getattr(a, f"{kind}_bridging_mode")
        if value is not None:
            o.modes[kind] = _mode(value, f"--{kind}_bridging_mode", allowed)
        custom = getattr(a, f"{kind}_topic_custom_bridging_mode")
        if custom is not None:
            o.custom_modes[kind] = _custom(custom, f"--{kind}_topic_custom_bridging_mode", allowed)
    if a.ros_master_polling_interval is not None:
        o.polling_interval = parse_duration(a.ros_master_polling_interval, "--ros_master_polling_interval")
    return o
