"""Oracle 1: the `rosbags` package's ROS 1 Noetic type store.

For every shipped message type rosbags knows: our md5sum equals the one rosbags computes from its own
definitions, and our full definition text (``_full_text``, what goes into connection headers and bags)
decodes with rosbags' ROS 1 parser to exactly the fields and constants of rosbags' definitions, for the
type itself and every type embedded in it. Types rosbags lacks (services, tf2_msgs, the tutorials) are
covered by the Debian oracle and the published md5 table.
"""

from __future__ import annotations

import pytest
from iface_inventory import SHIPPED_PACKAGES, inventory, package_of
from iface_published import PUBLISHED_MD5
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from ninjemys.idl.loader import get_message_class, get_service_class, message_class_from_definition

INV = inventory()
STORE = get_typestore(Stores.ROS1_NOETIC)


def rosbags_name(type_name: str) -> str:
    pkg, name = type_name.split("/", 1)
    return f"{pkg}/msg/{name}"


#: rosbags gives empty messages (std_msgs/Empty, empty service parts) this placeholder field; ROS 1 has none
ROSBAGS_PLACEHOLDER = "structure_needs_at_least_one_member"


def store_fields(rosbags_type: str) -> list:
    return [f for f in STORE.fielddefs[rosbags_type][1] if f[0] != ROSBAGS_PLACEHOLDER]


def ros1_name(rosbags_type: str) -> str:
    pkg, _, name = rosbags_type.split("/")
    return f"{pkg}/{name}"


IN_STORE = [t for t in INV.messages if rosbags_name(t) in STORE.fielddefs]


def test_store_covers_a_real_share_of_what_we_ship() -> None:
    # guards against a silently empty parametrization (e.g. a renamed interfaces directory)
    assert len(INV.messages) > 150
    assert len(IN_STORE) > 120


def test_every_noetic_type_rosbags_knows_is_shipped() -> None:
    """Completeness: no message of a shipped package that rosbags' Noetic store has is missing here."""
    ours = set(INV.messages)
    theirs = {ros1_name(t) for t in STORE.fielddefs if t.split("/")[0] in SHIPPED_PACKAGES and "/msg/" in t}
    assert sorted(theirs - ours) == []


@pytest.mark.parametrize("type_name", IN_STORE)
def test_md5_equals_rosbags(type_name: str) -> None:
    cls = get_message_class(type_name)
    _, expected = STORE.generate_msgdef(rosbags_name(type_name), ros_version=1)
    assert cls._md5sum == expected, type_name
    assert cls._type == type_name


@pytest.mark.parametrize("type_name", IN_STORE)
def test_full_text_decodes_to_rosbags_fields_and_constants(type_name: str) -> None:
    cls = get_message_class(type_name)
    decoded = get_types_from_msg(cls._full_text, rosbags_name(type_name))
    # the type itself and each embedded type, by rosbags' own parser, against rosbags' own store
    assert rosbags_name(type_name) in decoded
    for embedded, (constants, fields) in decoded.items():
        assert constants == STORE.fielddefs[embedded][0], f"{type_name}: constants of {embedded}"
        assert fields == store_fields(embedded), f"{type_name}: fields of {embedded}"
    # every dependency rosbags' own full text lists appears in ours too
    expected_text, _ = STORE.generate_msgdef(rosbags_name(type_name), ros_version=1)
    assert set(get_types_from_msg(expected_text, rosbags_name(type_name))) == set(decoded)


@pytest.mark.parametrize("type_name", sorted(PUBLISHED_MD5))
def test_md5_of_types_debian_lacks_equals_published(type_name: str) -> None:
    """turtlesim, rospy_tutorials, actionlib_tutorials: md5sums as real ROS 1 publishes them."""
    srv_names = set(INV.services)
    if type_name in srv_names:
        assert get_service_class(type_name)._md5sum == PUBLISHED_MD5[type_name]
    else:
        assert get_message_class(type_name)._md5sum == PUBLISHED_MD5[type_name]


def test_published_table_covers_every_type_of_packages_debian_lacks() -> None:
    from iface_inventory import NOT_IN_DEBIAN

    ours = {t for t in INV.messages + INV.services if package_of(t) in NOT_IN_DEBIAN}
    # gazebo_msgs' 34 types: Debian's genmsg computes each from our text (test_gazebo_msgs.py);
    # the published figures below anchor a sample of them
    ours = {t for t in ours if package_of(t) != "gazebo_msgs"}
    assert ours - set(PUBLISHED_MD5) == set()


@pytest.mark.parametrize("type_name", INV.all_message_like)
def test_our_decoder_reads_our_full_text_back(type_name: str) -> None:
    """message_class_from_definition (what we use for types we do not ship) rebuilds the same type."""
    cls = get_message_class(type_name)
    rebuilt = message_class_from_definition(type_name, cls._full_text)
    assert rebuilt._md5sum == cls._md5sum
    assert list(rebuilt.__slots__) == list(cls.__slots__)
    assert list(rebuilt._slot_types) == list(cls._slot_types)
