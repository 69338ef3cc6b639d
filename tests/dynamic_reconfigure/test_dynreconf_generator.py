"""The .cfg generator and the Config <-> message encoding, without a ROS graph."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest
import yaml
from dyn_fixtures import load_module, write_tutorial_module

from ninjemys.dynamic_reconfigure.encoding import (
    Config,
    decode_config,
    decode_description,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    initial_config,
)
from ninjemys.dynamic_reconfigure.generator import run_cfg
from ninjemys.errors import DefinitionError


@pytest.fixture
def tutorials(tmp_path: Path):
    return load_module(write_tutorial_module(tmp_path))


def test_generated_module_tables(tutorials) -> None:
    assert tutorials.defaults == {
        "int_param": 50,
        "double_param": 0.5,
        "str_param": "Hello World",
        "bool_param": True,
        "size": 1,
        "max_speed": 1.0,
        "inner_flag": False,
    }
    assert tutorials.min["int_param"] == 0 and tutorials.max["double_param"] == 1.0
    assert tutorials.min["str_param"] == "" and tutorials.max["bool_param"] is True
    assert tutorials.level["inner_flag"] == 8 and tutorials.all_level == 13
    assert tutorials.type["max_speed"] == "double"
    assert tutorials.Tutorials_Large == 2
    root = tutorials.config_description
    assert (root["name"], root["id"], root["lower"], root["class"]) == ("Default", 0, "groups", "DEFAULT")
    limits = root["groups"][0]
    assert (limits["name"], limits["id"], limits["parent"], limits["field"]) == (
        "Limits",
        1,
        0,
        "DEFAULT::limits",
    )
    inner = limits["groups"][0]
    assert (inner["id"], inner["parent"], inner["type"], inner["state"]) == (2, 1, "collapse", False)
    assert inner["class"] == "DEFAULT::LIMITS::INNER" and inner["parentname"] == "Limits"
    # srcline points at the .cfg line of each gen.add
    assert [p["srcline"] for p in root["parameters"]][:2] == [8, 9]


def test_unbounded_double_is_infinite(tmp_path: Path) -> None:
    cfg = tmp_path / "Free.cfg"
    cfg.write_text(
        "from dynamic_reconfigure.parameter_generator_catkin import *\n"
        "gen = ParameterGenerator()\n"
        'gen.add("x", double_t, 0, "free")\n'
        'exit(gen.generate("p", "n", "Free"))\n'
    )
    (gen,) = run_cfg(cfg, "p")
    from ninjemys.dynamic_reconfigure.generator import render_module

    (tmp_path / "FreeConfig.py").write_text(render_module(gen))
    module = load_module(tmp_path / "FreeConfig.py")
    assert module.min["x"] == -math.inf and module.max["x"] == math.inf and module.defaults["x"] == 0.0


@pytest.mark.parametrize(
    ("line", "reason"),
    [
        ('gen.add("speed", double_t, 0, "s", "fast")', "'speed' has type double, but default is 'fast'"),
        ('gen.add("9lives", int_t, 0, "s", 1)', "The name of field '9lives' does not follow the ROS naming"),
        (
            'gen.add("name", str_t, 0, "s", "a", "b", "c")',
            "Max or min specified for name, which is of 'str' type",
        ),
        ('gen.add("x", int_t, 0, "dup", 1)', "parameter 'x' is already defined at line 3"),
        ('gen.add("y", float_t, 0, "s", 1)', "NameError: name 'float_t' is not defined"),
        (
            'gen.add("e", int_t, 0, "s", 0, edit_method=gen.enum([gen.const("A", int_t, 0, "a"), gen.const("B", str_t, "b", "b")], "e"))',
            "Inconsistent types in enum!",
        ),
        ('gen.add("z", int_t, 0, "s", 1.5)', "'z' has type int, but default is 1.5"),
        ('gen.const("Q", int_t, 1, "it\'s")', "quotes not allowed in description string"),
    ],
)
def test_cfg_errors_name_file_and_line(tmp_path: Path, line: str, reason: str) -> None:
    cfg = tmp_path / "Bad.cfg"
    cfg.write_text(
        "from dynamic_reconfigure.parameter_generator_catkin import *\n"
        "gen = ParameterGenerator()\n"
        'gen.add("x", int_t, 0, "fine", 1)\n'
        f"{line}\n"
        'exit(gen.generate("p", "n", "Bad"))\n'
    )
    with pytest.raises(DefinitionError) as info:
        run_cfg(cfg, "p")
    assert str(info.value).startswith(f"{cfg}:4: ")
    assert reason in str(info.value)


def test_cfg_without_generate_and_syntax_error(tmp_path: Path) -> None:
    cfg = tmp_path / "Quiet.cfg"
    cfg.write_text(
        "from dynamic_reconfigure.parameter_generator_catkin import *\ngen = ParameterGenerator()\n"
    )
    with pytest.raises(DefinitionError, match=r"Quiet.cfg: never calls gen.generate"):
        run_cfg(cfg, "p")
    cfg.write_text("gen = (\n")
    with pytest.raises(DefinitionError, match=r"Quiet.cfg:1: invalid Python"):
        run_cfg(cfg, "p")


def test_encode_decode_round_trip(tutorials) -> None:
    descr = encode_description(tutorials)
    assert [g.name for g in descr.groups] == ["Default", "Limits", "Inner"]
    assert [(g.id, g.parent) for g in descr.groups] == [(0, 0), (1, 0), (2, 1)]
    assert {p.name: p.value for p in descr.max.ints} == {"int_param": 100, "size": 3}
    decoded = decode_description(descr)
    assert [p["name"] for p in extract_params(decoded)] == list(tutorials.defaults)
    assert decoded["groups"]["Limits"]["groups"]["Inner"]["state"] is True  # a Group message has no state

    config = Config(tutorials.defaults)
    config["groups"] = get_tree(descr)
    start = initial_config(encode_config(config), tutorials.config_description)
    assert start["groups"]["groups"]["Limits"]["groups"]["Inner"]["state"] is False
    assert start["groups"]["groups"]["Limits"]["parameters"] == {"max_speed": 1.0}
    msg = encode_config(start)
    assert [(g.name, g.state) for g in msg.groups] == [("Default", True), ("Inner", False), ("Limits", True)]
    back = decode_config(msg, decoded)
    assert back.int_param == 50 and back["groups"]["groups"]["Limits"]["max_speed"] == 1.0
    assert back["groups"]["groups"]["Limits"]["groups"]["Inner"]["inner_flag"] is False


def test_config_dict_behaves_like_ros1(tutorials) -> None:
    config = Config(tutorials.defaults)
    config.size = 3
    assert config["size"] == 3 and copy.deepcopy(config) == config
    with pytest.raises(KeyError):
        _ = config.missing
    text = yaml.dump(Config(a=1, groups=Config(b=True)))
    assert text.startswith("!!python/object/new:dynamic_reconfigure.encoding.Config\ndictitems:\n")
    assert "state: []" in text


def test_cfg_run_by_hand_like_cmake(tmp_path: Path) -> None:
    """ROS 1's CMake runs the script with four paths; the fourth gets <python dir>/cfg/<Name>Config.py."""
    import subprocess
    import sys

    from dyn_fixtures import TUTORIAL_CFG

    cfg = tmp_path / "Tutorials.cfg"
    cfg.write_text(TUTORIAL_CFG)
    out = tmp_path / "py"
    args = [sys.executable, str(cfg), str(tmp_path), str(tmp_path), str(tmp_path / "cpp"), str(out)]
    done = subprocess.run(args, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert load_module(out / "cfg" / "TutorialsConfig.py").defaults["size"] == 1
    assert (out / "cfg" / "__init__.py").is_file()
    alone = subprocess.run([sys.executable, str(cfg)], capture_output=True, text=True, timeout=60)
    assert alone.returncode == 1 and "catkin_make runs it for you" in alone.stderr
