"""rosmsg's Python API as ROS 1 programs import it: a type's definition as ``rosmsg show`` prints it
(``get_msg_text``/``get_srv_text``), the types of a package, the packages holding a type.

Definitions come from ninjemys.idl's loader (the parser every node uses), packages from the rospkg
facade; the ``rosmsg`` command is ninjemys.tools.rosmsg (the layering keeps facades below the tools).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from io import StringIO
from typing import Any

import rospkg
from ninjemys.errors import NinjemysError
from ninjemys.idl import loader

__all__ = [
    "MODE_MSG",
    "MODE_SRV",
    "ROSMsgException",
    "RosMsgProtoException",
    "RosMsgProtoArgsException",
    "spec_to_str",
    "get_msg_text",
    "get_srv_text",
    "rosmsg_debug",
    "list_msgs",
    "list_srvs",
    "list_types",
    "iterate_packages",
    "rosmsg_search",
    "rosmsg_md5",
    "rosmsgmain",
]

MODE_MSG = ".msg"
MODE_SRV = ".srv"


class ROSMsgException(Exception):
    """A type cannot be found or loaded."""


class RosMsgProtoException(Exception):
    """``rosmsg-proto`` could not build a prototype."""


class RosMsgProtoArgsException(Exception):
    """``rosmsg-proto`` was given bad arguments."""


def spec_to_str(msg_context: Any, spec: Any, buff: StringIO | None = None, indent: str = "") -> str:
    """The parsed form ``rosmsg show`` prints: constants, then fields, nested message types expanded
    below their field and indented two spaces (``msg_context`` is unused: our loader resolves types)."""
    if buff is None:
        buff = StringIO()
    for c in spec.constants:
        buff.write(f"{indent}{c.type} {c.name}={c.value_text}\n")
    for f in spec.fields:
        buff.write(f"{indent}{f.type} {f.name}\n")
        if f.type.is_message:
            spec_to_str(msg_context, loader.get_message_spec(f.type.base), buff, indent + "  ")
    return buff.getvalue()


def get_msg_text(type_: str, raw: bool = False, rospack: Any = None) -> str:
    """The definition of message ``type_``: as written with ``raw``, else parsed and expanded."""
    try:
        spec = loader.get_message_spec(type_)
        return spec.text if raw else spec_to_str(None, spec)
    except (NinjemysError, ValueError) as exc:
        raise ROSMsgException(f"Unable to load msg [{type_}]: {exc}") from None


def get_srv_text(type_: str, raw: bool = False, rospack: Any = None) -> str:
    """The definition of service ``type_``: request, ``---``, response."""
    try:
        spec = loader.get_service_spec(type_)
        return (
            spec.text if raw else spec_to_str(None, spec.request) + "---\n" + spec_to_str(None, spec.response)
        )
    except (NinjemysError, ValueError) as exc:
        raise ROSMsgException(f"Unknown srv type [{type_}]: {exc}") from None


def rosmsg_debug(rospack: Any, mode: str, type_: str, raw: bool = False) -> None:
    """Print the definition of ``type_`` in ``mode`` (MODE_MSG or MODE_SRV)."""
    if mode == MODE_SRV:
        print(get_srv_text(type_, raw=raw, rospack=rospack))
    elif mode == MODE_MSG:
        print(get_msg_text(type_, raw=raw, rospack=rospack))
    else:
        raise ROSMsgException(f"Invalid mode for debug: {mode}")


def _subdir(mode: str, what: str) -> str:
    if mode == MODE_MSG:
        return "msg"
    if mode == MODE_SRV:
        return "srv"
    raise ValueError(f"Unknown mode for {what}: {mode}")


def list_types(package: str, mode: str = MODE_MSG, rospack: Any = None) -> list[str]:
    """``pkg/Type`` for each definition file of ``mode`` in ``package`` (ResourceNotFound if unknown)."""
    subdir = _subdir(mode, "list_types")
    rospack = rospack or rospkg.RosPack()
    path = os.path.join(rospack.get_path(package), subdir)
    if not os.path.isdir(path):
        return []
    names = sorted(
        f[: -len(mode)]
        for f in os.listdir(path)
        if f.endswith(mode) and os.path.isfile(os.path.join(path, f))
    )
    return [f"{package}/{n}" for n in names]


def list_msgs(package: str, rospack: Any = None) -> list[str]:
    """The message types of ``package``."""
    return list_types(package, rospack=rospack)


def list_srvs(package: str, rospack: Any = None) -> list[str]:
    """The service types of ``package``."""
    return list_types(package, mode=MODE_SRV, rospack=rospack)


def iterate_packages(rospack: Any, mode: str) -> Iterator[tuple[str, str]]:
    """``(package, its msg or srv directory)`` for each package that has one."""
    subdir = _subdir(mode, "iterate_packages")
    for p in rospack.list():
        d = os.path.join(rospack.get_path(p), subdir)
        if os.path.isdir(d):
            yield p, d


def rosmsg_search(rospack: Any, mode: str, base_type: str) -> Iterator[str]:
    """``pkg/base_type`` for each package defining a type named ``base_type``."""
    for p, path in iterate_packages(rospack, mode):
        if os.path.isfile(os.path.join(path, f"{base_type}{mode}")):
            yield f"{p}/{base_type}"


def rosmsg_md5(mode: str, type_: str) -> str:
    """The md5sum of message (MODE_MSG) or service (MODE_SRV) ``type_``; IOError if it cannot load."""
    from roslib.message import get_message_class, get_service_class

    cls = get_message_class(type_) if mode == MODE_MSG else get_service_class(type_)
    if cls is None:
        raise OSError(f"cannot load [{type_}]")
    return cls._md5sum


def rosmsgmain(mode: str = MODE_MSG) -> None:
    """The ``rosmsg`` (MODE_MSG) or ``rossrv`` (MODE_SRV) command with sys.argv, as ROS 1's entry
    point: ours runs it; a failure exits with its status."""
    import subprocess
    import sys

    from ninjemys.commands import command_path

    code = subprocess.call([command_path("rossrv" if mode == MODE_SRV else "rosmsg"), *sys.argv[1:]])
    if code:
        sys.exit(code)
