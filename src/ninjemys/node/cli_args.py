"""Command-line arguments of a ROS 1 node: remappings, special keys and private parameters.

A node started as ``talker.py chatter:=/news __name:=t1 __ns:=robot _rate:=5`` must behave exactly as
under ROS 1, whether it is ours or rospy's. This module turns ``argv`` (plus the environment) into one
plain :class:`NodeArgs` value; it opens no socket and touches no global state, so the rospy facade,
the tools and launch can all share it and tests can check it without a master.

Precedence is ROS 1's: a special key on the command line (``__ns:=``, ``__master:=``, ``__ip:=``,
``__hostname:=``) wins over its environment variable (``ROS_NAMESPACE``, ``ROS_MASTER_URI``,
``ROS_IP``, ``ROS_HOSTNAME``). ``__name:=`` wins over the name given in code and over ``anonymous``.
Private parameter values (``_rate:=5``) are parsed as YAML, so ``5`` is an int, ``[1, 2]`` a list and
``'5'`` a string, as ``rospy.client.load_command_line_node_params`` does.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

from ninjemys import names
from ninjemys.errors import NameError_, ParameterError
from ninjemys.records import SlotRecord

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

DEFAULT_MASTER_URI = "http://localhost:11311/"

#: special keys of the form ``__key:=value`` and the environment variable each one overrides
SPECIAL_KEYS: dict[str, str | None] = {
    "__name": None,
    "__ns": "ROS_NAMESPACE",
    "__master": "ROS_MASTER_URI",
    "__ip": "ROS_IP",
    "__hostname": "ROS_HOSTNAME",
    "__log": None,
}


class NodeArgs(SlotRecord):
    """Everything ROS 1 reads from a node's command line and environment.

    ``remappings`` are the user ``from:=to`` pairs exactly as typed (unresolved); use
    :meth:`resolved_remappings` once the node's full name is known.

    A plain class rather than a dataclass: every node parses its arguments at start-up, and the
    dataclass machinery would cost more than the parsing.
    """

    __slots__ = (
        "name",
        "namespace",
        "master_uri",
        "ip",
        "hostname",
        "log_file",
        "remappings",
        "private_params",
        "argv",
    )

    def __init__(
        self,
        name: str | None = None,
        namespace: str = "/",
        master_uri: str = DEFAULT_MASTER_URI,
        ip: str | None = None,
        hostname: str | None = None,
        log_file: str | None = None,
        remappings: dict[str, str] | None = None,
        private_params: dict[str, Any] | None = None,
        argv: list[str] | None = None,
    ) -> None:
        self.name = name
        self.namespace = namespace
        self.master_uri = master_uri
        self.ip = ip
        self.hostname = hostname
        self.log_file = log_file
        self.remappings: dict[str, str] = {} if remappings is None else remappings
        self.private_params: dict[str, Any] = {} if private_params is None else private_params
        self.argv: list[str] = [] if argv is None else argv

    def node_name(self, name: str, anonymous: bool = False) -> str:
        """The node's base name: ``__name:=`` wins (and cancels anonymous), else ``name`` (made unique)."""
        if self.name is not None:
            return self.name
        if not name:
            raise NameError_("node name must not be empty")
        if names.SEP in name:
            raise NameError_(
                f"node name [{name}] must be a base name: namespaces are not allowed in node names"
            )
        return names.rospy_anonymous_name(name) if anonymous else name

    def full_name(self, base_name: str) -> str:
        """The node's global name in its namespace (``/ns/base``)."""
        return names.canonicalize_name(self.namespace + base_name)

    def resolved_remappings(self, full_node_name: str) -> dict[str, str]:
        """Remappings with both sides resolved for ``full_node_name``, as the node applies them."""
        return names.resolve_remappings(self.remappings, full_node_name)


def _special_value(argv: Sequence[str], key: str) -> str | None:
    """The last ``key:=value`` on the command line (ROS 1 lets a later one win)."""
    found = None
    prefix = key + names.REMAP
    for arg in argv:
        if arg.startswith(prefix):
            found = arg[len(prefix) :].strip()
    return found


def parse_param_value(text: str, param: str = "") -> Any:
    """Parse one ``_param:=text`` value as YAML (``5`` -> 5, ``true`` -> True, ``[1,2]`` -> list).

    PyYAML is imported only when a node actually has private parameters on its command line, so a plain
    ``rospy.init_node`` does not pay for it.
    """
    import yaml

    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        where = f"_{param}:={text}" if param else text
        problem = getattr(exc, "problem", None) or " ".join(str(exc).split())
        raise ParameterError(f"invalid command-line parameter {where}: not valid YAML ({problem})") from None


def private_params(argv: Sequence[str]) -> dict[str, Any]:
    """``_param:=value`` arguments as {"param": yaml_value}; empty names or values are ignored as in rospy."""
    params: dict[str, Any] = {}
    for arg in argv:
        if names.REMAP not in arg or not names.is_remap_arg(arg):
            continue
        src, dst = (part.strip() for part in arg.split(names.REMAP, 1))
        if len(src) > 1 and src[0] == "_" and src[1] != "_" and dst:
            params[src[1:]] = parse_param_value(dst, src[1:])
    return params


def user_remappings(argv: Sequence[str]) -> dict[str, str]:
    """The ``from:=to`` pairs that remap names (special ``__keys`` and ``_params`` excluded)."""
    return {src: dst for src, dst in names.load_mappings(argv).items() if not src.startswith("__")}


def parse_args(
    argv: Sequence[str], env: Mapping[str, str] | None = None, strict_names: bool = True
) -> NodeArgs:
    """Read a node's command line and environment the way ROS 1 does.

    ``argv`` is the full command line including the program name (``sys.argv``); the returned
    ``argv`` is what ``rospy.myargv()`` gives: the same list without any ``x:=y`` argument.
    ``strict_names=False`` takes any non-empty ``__name:=`` as given (rospy only warns about it).
    """
    env = os.environ if env is None else env
    argv = list(argv)
    name = _special_value(argv, "__name")
    if name is not None and strict_names and not names.is_legal_base_name(name):
        raise NameError_(
            f"__name:={name}: the node name must be a legal base name (a letter, then [A-Za-z0-9_])"
        )
    ns = _special_value(argv, "__ns")
    namespace = names.make_global_ns(ns if ns is not None else env.get("ROS_NAMESPACE", names.SEP))
    master = _special_value(argv, "__master") or env.get("ROS_MASTER_URI") or DEFAULT_MASTER_URI
    return NodeArgs(
        name=name,
        namespace=names.canonicalize_name(namespace) + ("" if namespace == names.SEP else names.SEP),
        master_uri=master,
        ip=_special_value(argv, "__ip") or env.get("ROS_IP") or None,
        hostname=_special_value(argv, "__hostname") or env.get("ROS_HOSTNAME") or None,
        log_file=_special_value(argv, "__log"),
        remappings=user_remappings(argv),
        private_params=private_params(argv),
        argv=names.strip_remap_args(argv),
    )


def network_env(args: NodeArgs) -> dict[str, str]:
    """Environment entries a node's transport must see for ``__ip:=``/``__hostname:=`` to take effect."""
    out: dict[str, str] = {}
    if args.hostname:
        out["ROS_HOSTNAME"] = args.hostname
    if args.ip:
        out["ROS_IP"] = args.ip
    return out
