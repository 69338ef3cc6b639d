"""Answers to roslaunch's query options, computed from the plan, formatted exactly as ROS 1 prints them.

``--nodes``, ``--args NODE``, ``--find-node NODE``, ``--dump-params``, ``--files``, ``--ros-args``.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Mapping

import yaml

from ninjemys.errors import LaunchError, NinjemysError
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.names import get_ros_namespace, ns_join
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.executables import Executable, find_executable

DEFAULT_MASTER_URI = "http://localhost:11311/"


def script_resolve_name(name: str, env: Mapping[str, str] | None = None) -> str:
    """A node name typed on the command line, resolved in ROS_NAMESPACE as roslaunch does."""
    if not name or name.startswith("/") or name.startswith("$"):
        return name
    return ns_join(get_ros_namespace(env=env), name)


def find_nodes(plan: LaunchPlan, node_name: str) -> list[NodeSpec]:
    return [n for n in plan.nodes + plan.tests if n.name and n.resolved_name == node_name]


def node_list(plan: LaunchPlan) -> str:
    return "\n".join(plan.node_names())


def node_environment(node: NodeSpec, master_uri: str, env: Mapping[str, str]) -> dict[str, str]:
    """The full environment of the node's process (roslaunch's setup_env)."""
    d = dict(env)
    d["ROS_MASTER_URI"] = master_uri
    d.pop("ROS_NAMESPACE", None)
    ns = node.namespace[:-1] if node.namespace.endswith("/") else node.namespace
    if ns:
        d["ROS_NAMESPACE"] = ns
    for name, value in node.env_args:
        d[name] = value
    return d


def node_executable(node: NodeSpec, index: PackageIndex | None = None) -> Executable:
    """The executable a node runs; LaunchError in roslaunch's words when it cannot be found."""
    index = index or PackageIndex.from_environment()
    try:
        manifest = index.find(node.package)
    except NinjemysError as exc:
        raise LaunchError(f"{node.filename}: node [{node.resolved_name}]: {exc}") from None
    try:
        return find_executable(manifest, node.type)
    except NinjemysError:
        raise LaunchError(
            f"Cannot locate node of type [{node.type}] in package [{node.package}]. Make sure file exists in "
            "package path and permission is set to executable (chmod +x)"
        ) from None


def node_command(node: NodeSpec, index: PackageIndex | None = None, display: bool = False) -> list[str]:
    """launch-prefix + executable + args + remaps + ``__name:=``; ``display`` gives ROS 1's path form."""
    exe = node_executable(node, index)
    args = shlex.split(node.args) + [f"{a}:={b}" for a, b in node.remap_args] + [f"__name:={node.name}"]
    prefix = shlex.split(node.launch_prefix) if node.launch_prefix else []
    if display:
        return prefix + [exe.display_path] + args
    return prefix + exe.command(args)


def node_args(
    plan: LaunchPlan, node_name: str, files: list[str], env: Mapping[str, str] | None = None
) -> str:
    """``roslaunch --args NODE``: changed environment as ``K="V"`` then the command line."""
    env = os.environ if env is None else env
    node_name = script_resolve_name(node_name, env)
    matches = find_nodes(plan, node_name)
    if not matches:
        names = "\n".join(f" * {n}" for n in plan.node_names())
        raise LaunchError(
            f"ERROR: Cannot find node named [{node_name}] in [{', '.join(files)}].\nNode names are:\n{names}"
        )
    if len(matches) > 1:
        raise LaunchError(f"ERROR: multiple nodes named [{node_name}] in [{', '.join(files)}].")
    node = matches[0]
    master_uri = env.get("ROS_MASTER_URI") or DEFAULT_MASTER_URI
    full = node_environment(node, master_uri, env)
    changed = [f'{k}="{v}"' for k, v in full.items() if env.get(k) != v]
    return " ".join(changed + node_command(node, display=True))


def find_node(plan: LaunchPlan, node_name: str, env: Mapping[str, str] | None = None) -> str | None:
    """``roslaunch --find-node NODE``: the file that declares it (None when no node has that name)."""
    matches = find_nodes(plan, script_resolve_name(node_name, env))
    if len(matches) > 1:
        raise LaunchError(f"ERROR: multiple nodes named [{node_name}].")
    return matches[0].filename if matches else None


def dump_params(plan: LaunchPlan) -> str:
    """``roslaunch --dump-params``: every parameter as YAML, keys sorted (ROS 1's exact layout)."""
    return yaml.safe_dump({str(k): v for k, v in plan.params.items()}) + "\n"


def ros_args(plan: LaunchPlan) -> str:
    """``roslaunch --ros-args``: the top-level args users may set, required ones first."""
    required = sorted((n, d or "undocumented") for n, (d, default) in plan.arg_docs.items() if not default)
    optional = sorted(
        (n, d or "undocumented", default) for n, (d, default) in plan.arg_docs.items() if default
    )
    lines = []
    if required:
        lines.append("Required Arguments:")
        lines += [f"  {n}: {d}" for n, d in required]
    if optional:
        lines.append("Optional Arguments:")
        lines += [f'  {n} (default "{v}"): {d}' for n, d, v in optional]
    return "\n".join(lines) if lines else "No arguments."
