"""Our parser reads each shipped type's full definition text back to the oracle's fields and constants.

``_full_text`` is split into its blocks (own text, then one per ``MSG: pkg/Type``) and each block is parsed
with ``ninjemys.idl.parser``; the resulting fields (name, resolved type) and constants (type, name, value)
must equal the rosbags Noetic store's (oracle 1) and Debian genpy's (oracle 2, ros1 marker).
"""

from __future__ import annotations

from typing import Any

import pytest
from iface_inventory import NOT_IN_DEBIAN, inventory, package_of
from iface_oracle import GenpyOracle
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.base import Nodetype

from ninjemys.idl.fulltext import split_full_text
from ninjemys.idl.loader import get_message_class
from ninjemys.idl.parser import parse_message
from ninjemys.idl.spec import FieldType, MsgSpec

INV = inventory()
STORE = get_typestore(Stores.ROS1_NOETIC)


def parsed_blocks(type_name: str) -> dict[str, MsgSpec]:
    cls = get_message_class(type_name)
    blocks = split_full_text(type_name, cls._full_text)
    assert next(iter(blocks)) == type_name, "the own text comes first"
    return {name: parse_message(text, name) for name, text in blocks.items()}


def rosbags_name(type_name: str) -> str:
    pkg, name = type_name.split("/", 1)
    return f"{pkg}/msg/{name}"


def _rosbags_element(base: str) -> tuple[Any, Any]:
    if base in ("time", "duration"):
        return (Nodetype.NAME, f"builtin_interfaces/msg/{base.capitalize()}")
    if FieldType(base).is_builtin:
        return (Nodetype.BASE, (base, 0))
    return (Nodetype.NAME, rosbags_name(base))


def as_rosbags(spec: MsgSpec) -> tuple[list[Any], list[Any]]:
    """Our spec in rosbags' fielddefs shape: ([(name, type, value)], [(name, node)])."""
    fields = []
    for f in spec.fields:
        node = _rosbags_element(f.type.base)
        if f.type.is_array and f.type.array_len is not None:
            node = (Nodetype.ARRAY, (node, f.type.array_len))
        elif f.type.is_array:
            node = (Nodetype.SEQUENCE, (node, 0))
        fields.append((f.name, node))
    constants = [(c.name, c.type, c.value) for c in spec.constants]
    return constants, fields


IN_STORE = [t for t in INV.all_message_like if rosbags_name(t) in STORE.fielddefs]


@pytest.mark.parametrize("type_name", IN_STORE)
def test_full_text_parses_to_rosbags_definitions(type_name: str) -> None:
    for embedded, spec in parsed_blocks(type_name).items():
        expected_constants, expected_fields = STORE.fielddefs[rosbags_name(embedded)][:2]
        # rosbags gives empty messages a placeholder field that ROS 1 does not have
        expected_fields = [f for f in expected_fields if f[0] != "structure_needs_at_least_one_member"]
        constants, fields = as_rosbags(spec)
        assert fields == expected_fields, f"{type_name}: fields of {embedded}"
        assert constants == expected_constants, f"{type_name}: constants of {embedded}"


@pytest.fixture(scope="module")
def genpy_described(genpy_oracle: GenpyOracle) -> dict[str, Any]:
    wanted: set[str] = set()
    for type_name in INV.all_message_like:
        if package_of(type_name) not in NOT_IN_DEBIAN:
            wanted.update(split_full_text(type_name, get_message_class(type_name)._full_text))
    return genpy_oracle.call("describe", types=sorted(wanted))


@pytest.mark.ros1
@pytest.mark.parametrize("type_name", [t for t in INV.all_message_like if package_of(t) not in NOT_IN_DEBIAN])
def test_full_text_parses_to_genpy_definitions(type_name: str, genpy_described: dict[str, Any]) -> None:
    for embedded, spec in parsed_blocks(type_name).items():
        expected = genpy_described[embedded]
        assert expected is not None, f"Debian lacks {embedded}"
        assert [f.name for f in spec.fields] == expected["slots"], embedded
        assert [str(f.type) for f in spec.fields] == expected["slot_types"], embedded
        assert {c.name: c.value for c in spec.constants} == expected["constants"], embedded
        assert spec.has_header == expected["has_header"], embedded
