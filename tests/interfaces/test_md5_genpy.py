"""Oracle 2: Debian's real ROS 1 (genpy classes under /usr/bin/python3).

For every shipped message, service part and service that Debian packages: our md5sum, field names,
field types, constants and header flag equal genpy's. And our full definition text, decoded the way a
real ROS 1 subscriber decodes a publisher's ``message_definition`` (genpy.dynamic), yields a class with
the same md5sum, fields and constants: so rosbag, rostopic echo and rqt read our texts correctly.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from iface_inventory import NOT_IN_DEBIAN, SHIPPED_PACKAGES, inventory, package_of
from iface_oracle import GenpyOracle
from iface_published import PUBLISHED_MD5

from ninjemys.idl.loader import get_message_class, get_service_class

pytestmark = pytest.mark.ros1

INV = inventory()
DEBIAN_MSG_LIKE = [t for t in INV.all_message_like if package_of(t) not in NOT_IN_DEBIAN]
DEBIAN_SERVICES = [t for t in INV.services if package_of(t) not in NOT_IN_DEBIAN]
DIST_PACKAGES = Path("/usr/lib/python3/dist-packages")


@pytest.fixture(scope="module")
def described(genpy_oracle: GenpyOracle) -> dict[str, Any]:
    """One oracle round trip for every type, not one per type."""
    return genpy_oracle.call("describe", types=DEBIAN_MSG_LIKE)


@pytest.fixture(scope="module")
def service_md5s(genpy_oracle: GenpyOracle) -> dict[str, str | None]:
    return genpy_oracle.call("srv_md5", types=DEBIAN_SERVICES)


def _constants_of(cls: type, names: list[str]) -> dict[str, Any]:
    return {name: getattr(cls, name) for name in names if hasattr(cls, name)}


def test_every_debian_type_of_a_shipped_package_is_shipped() -> None:
    """Completeness against what Debian generated: every msg and srv module has a shipped counterpart."""
    missing = []
    for pkg in SHIPPED_PACKAGES:
        if pkg in NOT_IN_DEBIAN:
            continue
        for kind, ours in (("msg", INV.messages), ("srv", INV.services)):
            for module in sorted((DIST_PACKAGES / pkg / kind).glob("_*.py")):
                if module.name == "__init__.py":
                    continue
                name = f"{pkg}/{module.stem[1:]}"
                if name not in ours:
                    missing.append(name)
    assert missing == []


@pytest.mark.parametrize("type_name", DEBIAN_MSG_LIKE)
def test_class_equals_genpy(type_name: str, described: dict[str, Any]) -> None:
    expected = described[type_name]
    assert expected is not None, f"Debian has no genpy class for {type_name}"
    cls = get_message_class(type_name)
    assert cls._md5sum == expected["md5"]
    assert list(cls.__slots__) == expected["slots"]
    assert list(cls._slot_types) == expected["slot_types"]
    assert bool(cls._has_header) == expected["has_header"]
    embedded = [line[5:] for line in cls._full_text.split("\n") if line.startswith("MSG: ")]
    assert embedded == expected["embedded"], "MSG: blocks of the full text in ROS 1's order"
    assert _constants_of(cls, list(expected["constants"])) == expected["constants"]
    for name, value in expected["constants"].items():
        assert type(getattr(cls, name)) is type(value), f"{type_name}.{name}"


@pytest.mark.parametrize("type_name", DEBIAN_SERVICES)
def test_service_md5_equals_genpy(type_name: str, service_md5s: dict[str, str | None]) -> None:
    srv = get_service_class(type_name)
    assert service_md5s[type_name] is not None
    assert srv._md5sum == service_md5s[type_name]
    assert srv._type == type_name
    assert srv._request_class._type == f"{type_name}Request"
    assert srv._response_class._type == f"{type_name}Response"


@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_ros1_decodes_our_full_text_to_the_same_type(type_name: str, genpy_oracle: GenpyOracle) -> None:
    """genpy.dynamic over our ``_full_text`` gives the same md5, fields and constants as the real type."""
    cls = get_message_class(type_name)
    decoded = genpy_oracle.call("decode_full_text", type=type_name, full_text=cls._full_text)
    expected_md5 = PUBLISHED_MD5.get(type_name, cls._md5sum)
    assert decoded["md5"] == expected_md5
    assert decoded["slots"] == list(cls.__slots__)
    assert decoded["slot_types"] == list(cls._slot_types)
    assert _constants_of(cls, list(decoded["constants"])) == decoded["constants"]
