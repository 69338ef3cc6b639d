"""Shared pieces of the dynamic_reconfigure tests: a .cfg file and its generated module."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

from ninjemys.dynamic_reconfigure.generator import render_module, run_cfg

TUTORIAL_CFG = """\
#!/usr/bin/env python
PACKAGE = "dyn_demo"

from dynamic_reconfigure.parameter_generator_catkin import *

gen = ParameterGenerator()

gen.add("int_param", int_t, 0, "An Integer parameter", 50, 0, 100)
gen.add("double_param", double_t, 0, "A double parameter", .5, 0, 1)
gen.add("str_param", str_t, 0, "A string parameter", "Hello World")
gen.add("bool_param", bool_t, 0, "A Boolean parameter", True)

size_enum = gen.enum([gen.const("Small", int_t, 0, "A small constant"),
                      gen.const("Medium", int_t, 1, "A medium constant"),
                      gen.const("Large", int_t, 2, "A large constant"),
                      gen.const("ExtraLarge", int_t, 3, "An extra large constant")],
                     "An enum to set size")

gen.add("size", int_t, 1, "A size parameter which is edited via an enum", 1, 0, 3, edit_method=size_enum)

limits = gen.add_group("Limits")
limits.add("max_speed", double_t, 4, "Top speed", 1.0, 0.0, 5.0)
inner = limits.add_group("Inner", type="collapse", state=False)
inner.add("inner_flag", bool_t, 8, "A flag deep down", False)

exit(gen.generate(PACKAGE, "dyn_demo_node", "Tutorials"))
"""


def write_tutorial_module(directory: Path) -> Path:
    """Generate TutorialsConfig.py into ``directory`` (importable by us and by ROS 1's Server)."""
    cfg = directory / "Tutorials.cfg"
    cfg.write_text(TUTORIAL_CFG)
    (gen,) = run_cfg(cfg, "dyn_demo")
    out = directory / "TutorialsConfig.py"
    out.write_text(render_module(gen))
    return out


def load_module(path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
