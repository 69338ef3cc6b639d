"""Configurations as dicts and as dynamic_reconfigure/Config messages, both ways.

A configuration travels as ``dynamic_reconfigure/Config`` (parameters split into bools, ints, strs
and doubles, plus a flat list of GroupState); a description as ``ConfigDescription`` (the group tree
flattened into a list linked by ``parent`` ids, and min/max/default as three Configs). Programs see
both as nested :class:`Config` dicts, the shape ROS 1's Python API hands out, so ``dynparam get``
prints and ``dynparam dump`` writes byte for byte what ROS 1's does.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping
from typing import Any

from ninjemys.idl.loader import get_message_class

# The kinds a parameter can have, in the order a Config message lists them.
PARAM_TYPES: dict[str, type] = {"bool": bool, "int": int, "str": str, "double": float}


class Config(dict):
    """A dict whose keys are also attributes (``config.speed``), as ROS 1's ``encoding.Config``.

    Its module is given as ``dynamic_reconfigure.encoding`` because ``dynparam dump`` writes it with
    a ``!!python/object/new:dynamic_reconfigure.encoding.Config`` tag, and files dumped by ROS 1
    must load here and the other way round.
    """

    __slots__ = ()

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            if name.startswith("__"):
                raise AttributeError(name) from None
            raise

    def __setattr__(self, name: str, value: Any) -> None:
        self[name] = value

    def __delattr__(self, name: str) -> None:
        del self[name]

    def __getstate__(self) -> list[Any]:
        return []

    def __setstate__(self, state: Any) -> None:
        return None

    def copy(self) -> Config:
        return Config(self)

    def __deepcopy__(self, memo: dict[int, Any]) -> Config:
        return Config({copy.deepcopy(k, memo): copy.deepcopy(v, memo) for k, v in self.items()})


Config.__module__ = "dynamic_reconfigure.encoding"


def _msg(name: str) -> Any:
    return get_message_class(f"dynamic_reconfigure/{name}")


def extract_params(group: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Every parameter description of a group tree, depth first (groups as a list or a name->group dict)."""
    params = list(group["parameters"])
    children = group["groups"]
    for child in children.values() if isinstance(children, Mapping) else children:
        params.extend(extract_params(child))
    return params


def _group_states(tree: Mapping[str, Any]) -> list[Any]:
    """The GroupState list of a state tree: the root first, then each subtree's groups before its own."""
    GroupState = _msg("GroupState")
    out = []

    def below(node: Mapping[str, Any]) -> None:
        for child in node["groups"].values():
            below(child)
            out.append(GroupState(child["name"], bool(child["state"]), child["id"], child["parent"]))

    out.append(GroupState(tree["name"], bool(tree["state"]), tree["id"], tree["parent"]))
    below(tree)
    return out


def encode_config(config: Mapping[str, Any], flat: bool = True) -> Any:
    """A ``dynamic_reconfigure/Config`` message from a name->value dict.

    A group entry is a state tree (``flat``, the form every caller in ROS 1 uses) or, with
    ``flat=False``, a list of group dicts taken as they are.
    """
    ConfigMsg, GroupState = _msg("Config"), _msg("GroupState")
    msg = ConfigMsg()
    kinds = {bool: (msg.bools, "BoolParameter"), int: (msg.ints, "IntParameter")}
    kinds[str] = (msg.strs, "StrParameter")
    kinds[float] = (msg.doubles, "DoubleParameter")
    for key, value in config.items():
        kind = kinds.get(type(value))
        if kind is not None:
            kind[0].append(_msg(kind[1])(key, value))
        elif isinstance(value, Mapping) and flat:
            msg.groups.extend(_group_states(value))
        elif isinstance(value, (list, tuple)) and not flat:
            msg.groups = [GroupState(g["name"], bool(g["state"]), g["id"], g["parent"]) for g in value]
    return msg


def encode_groups(parent: Any, group: Mapping[str, Any]) -> list[Any]:
    """The ``Group`` messages of a description tree (``group`` first, then its subgroups, depth first);
    ``parent`` is unused, as in ROS 1 (each group names its parent by id)."""
    Group, ParamDescription = _msg("Group"), _msg("ParamDescription")
    params = [
        ParamDescription(p["name"], p["type"], p["level"], p["description"], p["edit_method"])
        for p in group["parameters"]
    ]
    msg = Group(group["name"], group["type"], params, group["parent"], group["id"])
    out = [msg]
    for child in group["groups"]:
        out.extend(encode_groups(msg, child))
    return out


def encode_description(descr: Any) -> Any:
    """A ``ConfigDescription`` message from a generated ``<Name>Config`` module (or any object with
    ``config_description``, ``min``, ``max`` and ``defaults``)."""
    msg = _msg("ConfigDescription")()
    msg.max = encode_config(descr.max)
    msg.min = encode_config(descr.min)
    msg.dflt = encode_config(descr.defaults)
    msg.groups = encode_groups(None, descr.config_description)
    return msg


def get_parents(group: Mapping[str, Any], descriptions: Mapping[str, Any]) -> list[Any]:
    """The ancestors of ``group`` among ``descriptions['group']``, the root first."""
    parents: list[Any] = []
    for candidate in descriptions["group"]:
        if candidate["id"] == group["parent"]:
            parents.extend(get_parents(candidate, descriptions))
            parents.append(candidate)
    return parents


def group_dict(group: Any) -> Config:
    """The dict form of a Group or GroupState message (no children yet)."""
    return Config(
        {
            "id": group.id,
            "parent": group.parent,
            "name": group.name,
            "type": getattr(group, "type", ""),
            "state": getattr(group, "state", True),
            "groups": Config({}),
            "parameters": Config({}),
        }
    )


def _children(groups: Iterable[Any], parent: Any) -> list[Any]:
    return [g for g in groups if g.id != 0 and g.parent == parent.id]


def get_tree(m: Any, group: Any = None) -> Config:
    """The group state tree of a Config or ConfigDescription message (children keyed by name); below
    the root group (id 0) only the children, as in ROS 1."""
    if group is None:
        group = next(g for g in m.groups if g.id == 0)
    children = Config({})
    for g in _children(m.groups, group):
        node = group_dict(g)
        node["groups"] = get_tree(m, g)
        children[node["name"]] = node
    if group.id != 0:
        return children
    tree = group_dict(group)
    tree["groups"] = children
    return tree


def decode_description(msg: Any) -> Config:
    """A ConfigDescription message as a group tree whose ``parameters`` carry min/max/default."""
    mins, maxes, defaults = decode_config(msg.min), decode_config(msg.max), decode_config(msg.dflt)

    def params(group: Any) -> list[dict[str, Any]]:
        return [
            {
                "name": p.name,
                "min": mins[p.name],
                "max": maxes[p.name],
                "default": defaults[p.name],
                "type": p.type,
                "level": p.level,
                "description": p.description,
                "edit_method": p.edit_method,
            }
            for p in group.parameters
        ]

    def build(group: Any) -> Config:
        children = Config({})
        for g in _children(msg.groups, group):
            node = group_dict(g)
            node["parameters"] = params(g)
            node["groups"] = build(g)
            children[node["name"]] = node
        return children

    root_msg = next((g for g in msg.groups if g.id == 0), None)
    if root_msg is None:
        return Config({})
    root = group_dict(root_msg)
    root["parameters"] = params(root_msg)
    root["groups"] = build(root_msg)
    return root


def _flat(msg: Any) -> Config:
    return Config((p.name, p.value) for p in [*msg.bools, *msg.ints, *msg.strs, *msg.doubles])


def decode_config(msg: Any, description: Mapping[str, Any] | None = None) -> Config:
    """A Config message as a name->value dict; with a description (decoded, or a generated module's),
    ``groups`` holds the state tree with each group's parameter values in it."""
    config = _flat(msg)
    if msg.groups and description is not None:
        tree = get_tree(msg)
        config["groups"] = tree

        def fill(node: Config, descr: Mapping[str, Any]) -> None:
            for param in descr["parameters"]:
                if param["name"] in config:
                    node[param["name"]] = config[param["name"]]
            subs = descr["groups"]
            for child in node["groups"].values():
                for sub in subs.values() if isinstance(subs, Mapping) else subs:
                    if sub["name"] == child["name"]:
                        fill(child, sub)

        fill(tree, description)
    return config


def initial_config(msg: Any, description: Mapping[str, Any] | None = None) -> Config:
    """A server's starting configuration: like :func:`decode_config`, for a generated description
    (groups as lists); group states come from the description and values go under ``parameters``."""
    config = _flat(msg)
    if not msg.groups or description is None:
        return config

    def described_state(gid: int, descr: Mapping[str, Any]) -> bool | None:
        for sub in descr["groups"]:
            if sub["id"] == gid:
                return sub["state"]
            found = described_state(gid, sub)
            if found is not None:
                return found
        return None

    def build(group: Any) -> Config:
        children = Config({})
        for g in _children(msg.groups, group):
            node = group_dict(g)
            state = described_state(g.id, description)
            if state is not None:
                node["state"] = state
            node["groups"] = build(g)
            children[node["name"]] = node
        return children

    root_msg = next(g for g in msg.groups if g.id == 0)
    tree = group_dict(root_msg)
    tree["groups"] = build(root_msg)

    def fill(node: Config, descr: Mapping[str, Any]) -> None:
        for param in descr["parameters"]:
            node["parameters"][param["name"]] = config[param["name"]]
        for child in node["groups"].values():
            for sub in descr["groups"]:
                if sub["name"] == child["name"]:
                    fill(child, sub)

    fill(tree, description)
    config["groups"] = tree
    return config
