"""rosparam's Python API as ROS 1 programs and launch helpers import it: YAML files and strings to
``(dict, namespace)`` pairs, uploading them, getting, setting, deleting, listing and dumping
parameters.

YAML is ninjemys.paramyaml's ROS dialect (``!degrees``/``!radians``, ``rad(pi/2)``, ``!!binary``; the
one roslaunch and the ``rosparam`` command use), the parameter server is reached through the rosgraph
facade. The ``rosparam`` command itself is ninjemys.tools.rosparam (facades sit below the tools).
"""

from __future__ import annotations

import os
import sys
from typing import Any
from xmlrpc.client import Binary

import yaml

import rosgraph
from ninjemys.paramyaml import ParamYamlError, dump_yaml, load_yaml, load_yaml_documents
from rosgraph.names import (
    GLOBALNS,
    get_ros_namespace,
    make_caller_id,
    make_global_ns,
    ns_join,
    script_resolve_name,
)

__all__ = [
    "NAME",
    "NS",
    "RosParamException",
    "RosParamIOException",
    "RosParamYAMLError",
    "print_params",
    "load_file",
    "load_str",
    "get_param_server",
    "get_param",
    "dump_params",
    "delete_param",
    "set_param_raw",
    "set_param",
    "upload_params",
    "list_params",
    "script_resolve_name",
    "yamlmain",
]

NAME = "rosparam"
#: the key of a YAML document that names the namespace it loads into
NS = "_ns"
_IO_ERROR = "Unable to communicate with master!"


class RosParamException(Exception):
    """A rosparam operation failed (bad YAML, missing file, bad value)."""


class RosParamIOException(RosParamException):
    """The master could not be reached."""


class RosParamYAMLError(RosParamException, yaml.YAMLError):
    """Text that is not YAML: a yaml.YAMLError, as ROS 1 lets PyYAML's own through, and a
    RosParamException naming the file, line and column."""


def _get_caller_id() -> str:
    return make_caller_id(f"rosparam-{os.getpid()}")


def print_params(params: Any, ns: str) -> None:
    """Print ``ns/key=value`` for each leaf of ``params``."""
    if type(params) is dict:
        for k, v in params.items():
            if type(v) is dict:
                print_params(v, ns_join(ns, k))
            else:
                print(f"{ns_join(ns, k)}={v}")
    else:
        print(params)


def _binary(value: Any) -> Any:
    """``!!binary`` values as ROS 1's rosparam gives them: xmlrpc.client.Binary."""
    if isinstance(value, bytes):
        return Binary(value)
    if isinstance(value, dict):
        return {k: _binary(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_binary(v) for v in value]
    return value


def load_str(
    str: str, filename: str, default_namespace: str | None = None, verbose: bool = False
) -> list[tuple[Any, str]]:  # noqa: A002
    """``[(document, namespace), ...]`` of a YAML text: a document's ``_ns`` key moves it into that
    namespace (relative to ``default_namespace``, else ROS_NAMESPACE)."""
    default_namespace = default_namespace or get_ros_namespace()
    try:
        docs = load_yaml_documents(str)
    except ParamYamlError as exc:
        raise RosParamYAMLError(f"{filename}: {exc}") from None
    paramlist = []
    for doc in docs:
        doc = _binary(doc)
        if isinstance(doc, dict) and NS in doc:
            ns = ns_join(default_namespace, doc.pop(NS))
            if verbose:
                print(f"reading parameters into namespace [{ns}]")
        else:
            ns = default_namespace
        paramlist.append((doc, ns))
    return paramlist


def load_file(
    filename: str, default_namespace: str | None = None, verbose: bool = False
) -> list[tuple[Any, str]]:
    """load_str of a file (stdin for ``-`` or an empty name)."""
    if not filename or filename == "-":
        if verbose:
            print("reading parameters from stdin")
        return load_str(sys.stdin.read(), filename, default_namespace=default_namespace, verbose=verbose)
    if not os.path.isfile(filename):
        raise RosParamException(f"file [{filename}] does not exist")
    if verbose:
        print(f"reading parameters from [{filename}]")
    with open(filename) as f:
        return load_str(f.read(), filename, default_namespace=default_namespace, verbose=verbose)


def get_param_server() -> rosgraph.Master:
    """The master, as this process's rosparam caller id."""
    return rosgraph.Master(_get_caller_id())


def get_param(param: str) -> Any:
    """The value (a dict for a namespace) of ``param``; rosgraph.MasterError if it is not set."""
    try:
        return get_param_server().getParam(param)
    except OSError:
        raise RosParamIOException(_IO_ERROR) from None


def dump_params(filename: str | None, param: str, verbose: bool = False) -> None:
    """Write the tree under ``param`` as YAML to ``filename`` (stdout without one)."""
    tree = get_param(param)
    if verbose:
        print_params(tree, param)
    text = dump_yaml(tree)
    if not filename:
        sys.stdout.write(text)
    else:
        with open(filename, "w") as f:
            f.write(text)


def delete_param(param: str, verbose: bool = False) -> None:
    """Delete ``param`` (``/`` empties the whole server)."""
    try:
        if param == GLOBALNS:
            get_param_server().setParam(GLOBALNS, {})
            if verbose:
                print("deleted ENTIRE parameter server")
        else:
            get_param_server().deleteParam(param)
            if verbose:
                print(f"deleted parameter [{param}]")
    except OSError:
        raise RosParamIOException(_IO_ERROR) from None


def set_param_raw(param: str, value: Any, verbose: bool = False) -> None:
    """Set ``param`` to a Python value; a dict is set key by key (merged, not replacing)."""
    if type(value) is dict:
        for k, v in value.items():
            if not isinstance(k, str):
                raise RosParamException(
                    f"YAML dictionaries must have string keys. Invalid dictionary is:\n{value}"
                )
            set_param_raw(ns_join(param, k), v, verbose=verbose)
        return
    if type(value) is int and value > sys.maxsize:
        raise RosParamException(
            "Overflow: Parameter Server integers must be 32-bit signed integers:\n"
            f"\t-{sys.maxsize - 1} <= value <= {sys.maxsize}"
        )
    try:
        get_param_server().setParam(param, value)
    except OSError:
        raise RosParamIOException(_IO_ERROR) from None
    if verbose:
        print(f"set parameter [{param}] to [{value}]")


def set_param(param: str, value: str, verbose: bool = False) -> None:
    """Set ``param`` from a YAML text (``"1.5"``, ``"[1, 2]"``, ``"{a: 1}"``)."""
    try:
        parsed = load_yaml(value)
    except ParamYamlError as exc:
        raise RosParamYAMLError(str(exc)) from None
    set_param_raw(param, parsed, verbose=verbose)


def upload_params(ns: str, values: Any, verbose: bool = False) -> None:
    """Set every value of ``values`` under ``ns`` (``/`` takes only a dict)."""
    if ns == "/" and type(values) is not dict:
        raise RosParamException("global / can only be set to a dictionary")
    if verbose:
        print_params(values, ns)
    set_param_raw(ns, values)


def list_params(ns: str) -> list[str]:
    """The sorted parameter names under ``ns``."""
    try:
        prefix = make_global_ns(ns)
        return [n for n in sorted(get_param_server().getParamNames()) if n.startswith(prefix)]
    except OSError:
        raise RosParamIOException(_IO_ERROR) from None


def yamlmain(argv: list[str] | None = None) -> None:
    """The ``rosparam`` command with ``argv`` (``argv[0]`` is the program name), as ROS 1's entry point:
    our ``rosparam`` runs it; a failure exits with its status."""
    import subprocess

    from ninjemys.commands import command_path

    argv = sys.argv if argv is None else argv
    code = subprocess.call([command_path("rosparam"), *argv[1:]])
    if code:
        sys.exit(code)
