"""zenoh-bridge-ros1's key layout and command line (no Zenoh session, no ROS graph)."""

from __future__ import annotations

import pytest

from ninjemys.zenoh_bridge import keys
from ninjemys.zenoh_bridge.keys import Resource
from ninjemys.zenoh_bridge.options import OptionsError, parse_duration, parse_options

STRING = Resource("/robot/chatter", "std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1")


def test_data_key_is_the_rust_layout():
    # hex(datatype)/md5/bridge_ns/topic without the leading slash (zenoh-plugin-ros1's topic_utilities)
    assert keys.data_key(STRING, "robot7") == (
        "7374645f6d7367732f537472696e67/992ce8a1687cec8c8bd883ec73ca41d1/robot7/robot/chatter"
    )
    assert keys.data_key(STRING, "*").split("/")[2] == "*"


def test_discovery_key_round_trips():
    key = keys.discovery_key(STRING, keys.PUB, "robot7")
    assert key.startswith("ros1_discovery_info/*/pub/7374645f6d7367732f537472696e67/")
    assert keys.parse_discovery(key) == (keys.PUB, STRING)
    assert keys.discovery_selector("robot7") == "ros1_discovery_info/*/*/*/*/robot7/*/**"


@pytest.mark.parametrize(
    "key",
    [
        "ros1_discovery_info/*/pub/zz/md5/ns/t",
        "ros1_discovery_info/*/bogus/61/md5/ns/t",
        "other/*/pub/61/m/ns/t",
        "x",
    ],
)
def test_bad_discovery_keys_are_named(key):
    with pytest.raises(keys.KeyError_, match="discovery key"):
        keys.parse_discovery(key)


def test_defaults_are_the_rust_bridges():
    o = parse_options([], env={})
    assert (o.mode, o.bridge_namespace, o.ros_name) == ("peer", "*", "ros1_to_zenoh_bridge")
    assert o.modes == {"subscriber": "auto", "publisher": "auto", "service": "auto", "client": "disabled"}
    assert o.ros_master_uri == "http://localhost:11311/"
    assert o.polling_interval == pytest.approx(0.1)
    assert o.multicast_scouting


def test_options_map_to_zenoh_and_modes():
    o = parse_options(
        [
            "-m", "client", "-e", "tcp/10.0.0.1:7447", "-l", "tcp/0.0.0.0:7448", "--no-multicast-scouting",
            "--bridge_namespace", "robot1", "--client_bridging_mode", "auto",
            "--publisher_topic_custom_bridging_mode", '{"/odom": "lazy_auto", "scan": "disabled"}',
            "--ros_master_polling_interval", "2s", "--ros_master_uri", "http://h:1234/",
        ],
        env={},
    )  # fmt: skip
    assert o.zenoh_config_json() == {
        "mode": "client",
        "connect/endpoints": ["tcp/10.0.0.1:7447"],
        "listen/endpoints": ["tcp/0.0.0.0:7448"],
        "scouting/multicast/enabled": False,
    }
    assert o.mode_for("publisher", "/odom") == "lazy_auto"
    assert o.mode_for("publisher", "/scan") == "disabled"
    assert o.mode_for("publisher", "/other") == "auto"
    assert o.mode_for("client", "/x") == "auto"
    assert o.polling_interval == 2.0
    assert o.ros_master_uri == "http://h:1234/"


def test_environment_fills_master_and_namespace():
    o = parse_options([], env={"ROS_MASTER_URI": "http://m:11312/", "BRIDGE_NAMESPACE": "r2"})
    assert (o.ros_master_uri, o.bridge_namespace) == ("http://m:11312/", "r2")


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["-e", "127.0.0.1:7447"], "--connect: bad endpoint '127.0.0.1:7447'"),
        (["-l", "tcp/127.0.0.1"], "--listen: bad endpoint 'tcp/127.0.0.1'"),
        (["-e", "carrier-pigeon/x:1"], "--connect: bad endpoint"),
        (
            ["--subscriber_bridging_mode", "eager"],
            "--subscriber_bridging_mode: unknown bridging mode 'eager'",
        ),
        (["--client_bridging_mode", "lazy_auto"], "--client_bridging_mode: unknown bridging mode"),
        (["--service_topic_custom_bridging_mode", "[1]"], "expected a JSON object"),
        (["--service_topic_custom_bridging_mode", "{"], "not JSON"),
        (
            ["--ros_master_polling_interval", "fast"],
            "--ros_master_polling_interval: 'fast' is not a duration",
        ),
        (["--bridge_namespace", "a/b"], "--bridge_namespace"),
        (["--ros_master_uri", "localhost:11311"], "--ros_master_uri"),
        (["--with_rosmaster", "yes"], "--with_rosmaster"),
        (["--id", "xyz"], "--id"),
        (["--rest-http-port", "8000"], "--rest-http-port"),
        (["-c", "/nonexistent/zenoh.json5"], "--config: no such file"),
    ],
)
def test_bad_values_give_one_error_naming_the_option(argv, named):
    with pytest.raises(OptionsError, match=named.replace("[", r"\[").replace("{", r"\{")):
        parse_options(argv, env={})


def test_durations():
    assert parse_duration("100ms", "x") == pytest.approx(0.1)
    assert parse_duration("5m", "x") == 300.0
