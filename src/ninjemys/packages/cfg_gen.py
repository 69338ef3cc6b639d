"""catkin_make's dynamic_reconfigure step: ``cfg/*.cfg`` -> ``devel/.../<pkg>/cfg/<Name>Config.py``.

ROS 1 needs ``generate_dynamic_reconfigure_options(cfg/Foo.cfg)`` in CMakeLists.txt; here every
``.cfg`` file in a package's ``cfg/`` directory is generated, no CMake edit needed. Each script is run
in-process (:func:`ninjemys.dynamic_reconfigure.generator.run_cfg`); a mistake in one fails the build
with ``path:line: reason`` (a DefinitionError, which catkin_make reports for the package).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ninjemys.packages.manifest import PackageManifest


def cfg_files(pkg: PackageManifest) -> list[Path]:
    """The package's ``cfg/*.cfg`` files, sorted."""
    directory = pkg.path / "cfg"
    return sorted(directory.glob("*.cfg")) if directory.is_dir() else []


def generate(pkg: PackageManifest, dist: Path, writer: Any) -> bool:
    """Write the Config modules of ``pkg`` under ``dist/<pkg>/cfg/``; True when the package has any.

    ``writer.write(path, text)`` is catkin_make's write-if-changed (it also keeps the outputs listed
    so the modules of a deleted .cfg are removed on the next build).
    """
    files = cfg_files(pkg)
    if not files:
        return False
    from ninjemys.dynamic_reconfigure.generator import render_module, run_cfg

    target = dist / pkg.name / "cfg"
    for path in files:
        for gen in run_cfg(path, pkg.name):
            writer.write(target / f"{gen.name}Config.py", render_module(gen))
    writer.write(target / "__init__.py", "")
    return True
