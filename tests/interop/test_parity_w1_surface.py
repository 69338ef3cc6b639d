"""The public surface of our rosgraph, genpy, rostopic, rosnode, rosservice, rosparam, rosmsg and
roslaunch against Debian's, name by name, with test_parity_api's comparison (parameter names, kinds,
defaults, exception bases): what Debian has and we do not is listed in ALLOWED with the reason."""

from __future__ import annotations

import sys

import pytest
import test_parity_api as api

from ninjemys import testing

pytestmark = pytest.mark.ros1

PACKAGES = {
    "rosgraph": ["rosgraph", "rosgraph.names", "rosgraph.network", "rosgraph.masterapi", "rosgraph.rosenv"],
    "genpy": ["genpy", "genpy.message", "genpy.rostime", "genpy.base", "genpy.dynamic"],
    "rostopic": ["rostopic"],
    "rosnode": ["rosnode"],
    "rosservice": ["rosservice"],
    "rosparam": ["rosparam"],
    "rosmsg": ["rosmsg"],
    "roslaunch": [
        "roslaunch",
        "roslaunch.parent",
        "roslaunch.scriptapi",
        "roslaunch.rlutil",
        "roslaunch.core",
    ],
}

_MSG = "our generated messages' base class (ninjemys.idl.message.Message): ``__init__(self, /, *args, **kwargs)`` and ``deserialize(data)`` name their parameters differently; positional use is the same"
_ERR = "our messages raise ninjemys.errors' Serialization/DeserializationError (also what genpy exports), not subclasses of genpy.MessageException (docs/parity.md)"
_TOTIME = "genpy.Time is ninjemys.rostime.Time (rospy's); the deprecated to_time alias of to_sec is not there"
_PY2 = "Python 2 compatibility names or incidental imports of ROS 1's module, not API"
_UNICODE = "ROS 1's decoding-error policy for strings; ours decodes invalid UTF-8 with surrogateescape always"
_CLI = "internals of the command-line tools (option parsing, stdin/file YAML readers, echo formatting, prototypes): the commands are ninjemys.tools'; the *main() entry points run them"
_YAML = "PyYAML hooks rosparam registers globally; our YAML dialect (ninjemys.paramyaml) has its own loader and does not change PyYAML's global one"
_LAUNCH = "roslaunch's internal machinery (XML loader, config, runner, process monitor, XML-RPC server, remote launch): ours is ninjemys.launch, driven by ROSLaunchParent and scriptapi.ROSLaunch"

#: what Debian has and ours does not (or differently): path -> reason
ALLOWED: dict[str, str] = {
    "genpy.Message.__init__": _MSG,
    "genpy.Message.deserialize": _MSG,
    "genpy.message.Message.__init__": _MSG,
    "genpy.message.Message.deserialize": _MSG,
    "genpy.SerializationError": _ERR,
    "genpy.DeserializationError": _ERR,
    "genpy.message.SerializationError": _ERR,
    "genpy.message.DeserializationError": _ERR,
    "genpy.Time.to_time": _TOTIME,
    "genpy.message.Time.to_time": _TOTIME,
    "genpy.rostime.Time.to_time": _TOTIME,
    "genpy.message.long": _PY2,
    "genpy.dynamic.MsgContext": _PY2,
    "genpy.dynamic.StringIO": _PY2,
    "genpy.dynamic.msg_generator": _PY2,
    "rosgraph.network.BytesIO": _PY2,
    "rosnode.OptionParser": _PY2,
    "rosparam.OptionParser": _PY2,
    "rosservice.BufferType": _PY2,
    "genpy.message.reload": _PY2,
    "rosgraph.masterapi.ServerProxy": _PY2,
    "rosgraph.masterapi.parse_http_host_and_port": _PY2,
    "roslaunch.core.basestring": _PY2,
    "roslaunch.core.unicode": _PY2,
    "roslaunch.core.ServerProxy": _PY2,
    "rostopic.Fault": _PY2,
    "rostopic.itemgetter": _PY2,
    "rostopic.long": _PY2,
    "rostopic.urlparse": _PY2,
    "rosmsg.OptionParser": _PY2,
    "rosservice.OptionParser": _PY2,
    "rosmsg.find_in_workspaces": _PY2,
    "rosmsg.generate_dynamic": _PY2,
    "roslaunch.parent.printerrlog": _PY2,
    "roslaunch.parent.printlog_bold": _PY2,
    "genpy.message.RosMsgUnicodeErrors": _UNICODE,
    "rostopic.argv_publish": _CLI,
    "rosmsg.MAX_DEFAULT_NON_FLOW_ITEMS": _CLI,
    "rostopic.CallbackEcho": _CLI,
    "rostopic.create_field_filter": _CLI,
    "rostopic.create_value_transform": _CLI,
    "rostopic.file_yaml_arg": _CLI,
    "rostopic.param_publish": _CLI,
    "rostopic.param_publish_once": _CLI,
    "rostopic.stdin_publish": _CLI,
    "rostopic.stdin_yaml_arg": _CLI,
    "rostopic.wait_for_subscriber": _CLI,
    "rosmsg.construct_ordered_mapping": _CLI,
    "rosmsg.construct_yaml_map_with_ordered_dict": _CLI,
    "rosmsg.create_names_filter": _CLI,
    "rosmsg.fullusage": _CLI,
    "rosmsg.get_array_type_instance": _CLI,
    "rosmsg.get_yaml_for_msg": _CLI,
    "rosmsg.init_rosmsg_proto": _CLI,
    "rosmsg.represent_ordered_mapping": _CLI,
    "rosmsg.rosmsg_cmd_list": _CLI,
    "rosmsg.rosmsg_cmd_md5": _CLI,
    "rosmsg.rosmsg_cmd_package": _CLI,
    "rosmsg.rosmsg_cmd_packages": _CLI,
    "rosmsg.rosmsg_cmd_prototype": _CLI,
    "rosmsg.rosmsg_cmd_show": _CLI,
    "roslaunch.handle_exception": _CLI,
    "roslaunch.write_pid_file": _CLI,
    "roslaunch.rlutil.change_terminal_name": _CLI,
    "roslaunch.rlutil.check_log_disk_usage": _CLI,
    "roslaunch.rlutil.print_file_list": _CLI,
    "roslaunch.rlutil.update_terminal_name": _CLI,
    "rosparam.construct_angle_degrees": _YAML,
    "rosparam.construct_angle_radians": _YAML,
    "rosparam.construct_yaml_binary": _YAML,
    "rosparam.pattern": _YAML,
    "rosparam.represent_foo": _YAML,
    "rosparam.represent_xml_binary": _YAML,
    "roslaunch.depends": _LAUNCH,
    "roslaunch.config": _LAUNCH,
    "roslaunch.launch": _LAUNCH,
    "roslaunch.loader": _LAUNCH,
    "roslaunch.node_args": _LAUNCH,
    "roslaunch.nodeprocess": _LAUNCH,
    "roslaunch.param_dump": _LAUNCH,
    "roslaunch.pmon": _LAUNCH,
    "roslaunch.server": _LAUNCH,
    "roslaunch.substitution_args": _LAUNCH,
    "roslaunch.xmlloader": _LAUNCH,
    "roslaunch.Master": _LAUNCH,
    "roslaunch.Process": _LAUNCH,
    "roslaunch.ROSLaunchConfig": _LAUNCH,
    "roslaunch.ROSLaunchRunner": _LAUNCH,
    "roslaunch.Test": _LAUNCH,
    "roslaunch.XmlLoader": _LAUNCH,
    "roslaunch.XmlParseException": _LAUNCH,
    "roslaunch.parent.load_config_default": _LAUNCH,
    "roslaunch.scriptapi.Master": _LAUNCH,
    "roslaunch.rlutil.check_roslaunch": _LAUNCH,
    "roslaunch.core.Executable": _LAUNCH,
    "roslaunch.core.Machine": _LAUNCH,
    "roslaunch.core.Master": _LAUNCH,
    "roslaunch.core.MultiCall": _LAUNCH,
    "roslaunch.core.Param": _LAUNCH,
    "roslaunch.core.RosbinExecutable": _LAUNCH,
    "roslaunch.core.Test": _LAUNCH,
    "roslaunch.core.get_master_uri_env": _LAUNCH,
    "roslaunch.core.get_ros_package_path": _LAUNCH,
    "roslaunch.core.get_ros_root": _LAUNCH,
    "roslaunch.core.is_child_mode": _LAUNCH,
    "roslaunch.core.is_machine_local": _LAUNCH,
    "roslaunch.core.local_machine": _LAUNCH,
    "roslaunch.core.remap_localhost_uri": _LAUNCH,
    "roslaunch.core.rle_wrapper": _LAUNCH,
    "roslaunch.core.set_child_mode": _LAUNCH,
    "roslaunch.core.setup_env": _LAUNCH,
}


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_public_surface_matches_ros1(package: str, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(api, "PACKAGES", {**api.PACKAGES, **PACKAGES})
    monkeypatch.setattr(api, "ALLOWED", {**api.ALLOWED, **ALLOWED})
    theirs = api.dump(testing.ROS1_PYTHON, package, testing.ros1_env("http://localhost:11311"))
    ours = api.dump(sys.executable, package, None)
    problems = api.differences(package, theirs, ours)
    assert not problems, "\n".join(problems)


def test_allow_list_names_only_real_differences(monkeypatch: pytest.MonkeyPatch) -> None:
    """Every allowance is for something Debian has (a stale entry would hide a future regression)."""
    monkeypatch.setattr(api, "PACKAGES", {**api.PACKAGES, **PACKAGES})
    known = set()
    for package in PACKAGES:
        dumped = api.dump(testing.ROS1_PYTHON, package, testing.ros1_env("http://localhost:11311"))
        known |= {f"{package}.{s}" for s in dumped["<submodules>"]}
        for mod, names in dumped.items():
            if mod == "<submodules>" or "<error>" in names:
                continue
            for name, t in names.items():
                known.add(f"{mod}.{name}")
                known |= {f"{mod}.{name}.{m}" for m in t.get("members", {})}
    assert set(ALLOWED) <= known, sorted(set(ALLOWED) - known)
