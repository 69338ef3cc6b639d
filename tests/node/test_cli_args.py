"""Command-line remapping, special keys and private parameters, checked against ROS 1's rules."""

from __future__ import annotations

import pytest

from ninjemys.errors import NameError_, ParameterError
from ninjemys.node.cli_args import DEFAULT_MASTER_URI, parse_args


def test_plain_command_line_has_defaults() -> None:
    args = parse_args(["talker.py", "--verbose"], env={})
    assert args.name is None
    assert args.namespace == "/"
    assert args.master_uri == DEFAULT_MASTER_URI
    assert args.remappings == {}
    assert args.private_params == {}
    assert args.argv == ["talker.py", "--verbose"]


def test_remappings_and_myargv() -> None:
    args = parse_args(["talker.py", "chatter:=/news", "~out:=other", "hello"], env={})
    assert args.remappings == {"chatter": "/news", "~out": "other"}
    assert args.argv == ["talker.py", "hello"]
    assert args.resolved_remappings("/ns/talker") == {"/ns/chatter": "/news", "/ns/talker/out": "/ns/other"}


def test_special_keys_override_environment() -> None:
    env = {
        "ROS_NAMESPACE": "envns",
        "ROS_MASTER_URI": "http://envhost:1/",
        "ROS_IP": "10.0.0.1",
        "ROS_HOSTNAME": "envhost",
    }
    args = parse_args(
        [
            "n",
            "__name:=t1",
            "__ns:=/robot",
            "__master:=http://m:2/",
            "__ip:=1.2.3.4",
            "__hostname:=h",
            "__log:=/x.log",
        ],
        env=env,
    )
    assert args.name == "t1"
    assert args.namespace == "/robot/"
    assert args.master_uri == "http://m:2/"
    assert args.ip == "1.2.3.4"
    assert args.hostname == "h"
    assert args.log_file == "/x.log"
    assert args.remappings == {}
    assert args.argv == ["n"]


def test_environment_used_without_special_keys() -> None:
    args = parse_args(
        ["n"], env={"ROS_NAMESPACE": "a/b", "ROS_MASTER_URI": "http://h:3/", "ROS_HOSTNAME": "hh"}
    )
    assert args.namespace == "/a/b/"
    assert args.master_uri == "http://h:3/"
    assert args.hostname == "hh"
    assert args.ip is None


def test_private_params_are_yaml_typed() -> None:
    args = parse_args(
        ["n", "_rate:=5", "_gain:=0.5", "_on:=true", "_s:='5'", "_l:=[1, 2]", "_name:=abc"], env={}
    )
    assert args.private_params == {"rate": 5, "gain": 0.5, "on": True, "s": "5", "l": [1, 2], "name": "abc"}
    assert args.remappings == {}


def test_invalid_yaml_param_names_the_argument() -> None:
    with pytest.raises(ParameterError, match=r"_bad:=\[1"):
        parse_args(["n", "_bad:=[1"], env={})


def test_name_override_beats_anonymous() -> None:
    args = parse_args(["n", "__name:=fixed"], env={})
    assert args.node_name("talker", anonymous=True) == "fixed"
    plain = parse_args(["n"], env={})
    anon = plain.node_name("talker", anonymous=True)
    assert anon.startswith("talker_") and anon != "talker"
    assert plain.node_name("talker") == "talker"
    assert plain.full_name("talker") == "/talker"
    assert parse_args(["n", "__ns:=r1"], env={}).full_name("talker") == "/r1/talker"


def test_bad_names_are_rejected() -> None:
    with pytest.raises(NameError_):
        parse_args(["n", "__name:=a/b"], env={})
    with pytest.raises(NameError_, match="base name"):
        parse_args(["n"], env={}).node_name("a/b")
    with pytest.raises(NameError_):
        parse_args(["n"], env={}).node_name("")


def test_last_special_key_wins() -> None:
    assert parse_args(["n", "__name:=a", "__name:=b"], env={}).name == "b"
