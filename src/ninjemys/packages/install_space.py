"""``catkin_make install``: the install space, laid out as catkin lays it out.

What real catkin puts under ``install/`` (CMAKE_INSTALL_PREFIX) for Python packages, and so what
this writes, from the same CMakeLists.txt:

* ``setup.sh`` / ``setup.bash`` / ``setup.zsh`` / ``local_setup.*``: sourcing them makes the
  installed packages visible (ROS_PACKAGE_PATH gets ``share``, PYTHONPATH
  ``lib/python3/dist-packages``, CMAKE_PREFIX_PATH the prefix), over the underlays;
* ``share/<pkg>/package.xml`` (catkin_package) and ``share/<pkg>/{msg,srv,action}/`` (what
  add_message_files & co install);
* ``lib/python3/dist-packages/<module>/``: the catkin_python_setup() packages, copied, with the
  message and service modules of the package;
* ``lib/python3/dist-packages/<pkg>/cfg/``: the dynamic_reconfigure Config modules of the
  package's ``cfg/*.cfg`` (what generate_dynamic_reconfigure_options installs), with an empty
  ``<pkg>/__init__.py`` when catkin_python_setup() installs none;
* ``lib/<pkg>/<script>``: catkin_install_python(PROGRAMS ...) scripts, executable;
* whatever ``install(FILES|PROGRAMS|DIRECTORY ... DESTINATION ...)`` names, e.g. the tutorials'
  ``install(DIRECTORY launch DESTINATION ${CATKIN_PACKAGE_SHARE_DESTINATION})``. As with catkin, a
  launch/ directory no install() rule names is not installed (catkin_make says so).

The install space is a copy: it works once the sources are gone. ``install(TARGETS ...)`` and the
other install rules of C++ packages that catkin's CMake built (where a toolchain exists,
:mod:`ninjemys.packages.cpp_build`) are run by CMake's ``make install`` before this; without a
toolchain they are the C++ targets the build already reported as not built.
"""

from __future__ import annotations

import fnmatch
import json
import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages import cfg_gen
from ninjemys.packages.builder import STUB
from ninjemys.packages.cmake_hints import read_cmake_hints
from ninjemys.packages.manifest import MANIFEST, PackageManifest
from ninjemys.packages.python_setup import python_packages
from ninjemys.packages.setup_scripts import (
    MARKER,
    WorkspaceEnv,
    render_setup_bash,
    render_setup_sh,
    render_setup_zsh,
    underlay_workspaces,
)
from ninjemys.packages.workspace import Workspace

_COMMENT = re.compile(r"#[^\n]*")
_INSTALL = re.compile(r"\binstall\s*\(([^()]*)\)", re.IGNORECASE | re.S)
_KEYWORDS = frozenset(
    {
        "FILES",
        "PROGRAMS",
        "DIRECTORY",
        "TARGETS",
        "CODE",
        "SCRIPT",
        "DESTINATION",
        "PERMISSIONS",
        "FILE_PERMISSIONS",
        "DIRECTORY_PERMISSIONS",
        "USE_SOURCE_PERMISSIONS",
        "OPTIONAL",
        "MESSAGE_NEVER",
        "FILES_MATCHING",
        "PATTERN",
        "REGEX",
        "EXCLUDE",
        "RENAME",
        "COMPONENT",
        "CONFIGURATIONS",
    }
)


@dataclass(frozen=True)
class InstallRule:
    """One ``install(FILES|PROGRAMS|DIRECTORY ...)`` call of a package's CMakeLists.txt."""

    kind: str
    items: tuple[str, ...]
    destination: str
    patterns: tuple[str, ...]
    excludes: tuple[str, ...]
    files_matching: bool
    optional: bool
    line: int


def destinations(package: str) -> dict[str, str]:
    """catkin's destination variables (catkin_destinations.cmake), relative to the prefix."""
    return {
        "CATKIN_PACKAGE_BIN_DESTINATION": f"lib/{package}",
        "CATKIN_PACKAGE_ETC_DESTINATION": f"etc/{package}",
        "CATKIN_PACKAGE_INCLUDE_DESTINATION": f"include/{package}",
        "CATKIN_PACKAGE_LIB_DESTINATION": "lib",
        "CATKIN_PACKAGE_PYTHON_DESTINATION": f"lib/python3/dist-packages/{package}",
        "CATKIN_PACKAGE_SHARE_DESTINATION": f"share/{package}",
        "CATKIN_GLOBAL_BIN_DESTINATION": "bin",
        "CATKIN_GLOBAL_ETC_DESTINATION": "etc",
        "CATKIN_GLOBAL_INCLUDE_DESTINATION": "include",
        "CATKIN_GLOBAL_LIB_DESTINATION": "lib",
        "CATKIN_GLOBAL_LIBEXEC_DESTINATION": "lib",
        "CATKIN_GLOBAL_PYTHON_DESTINATION": "lib/python3/dist-packages",
        "CATKIN_GLOBAL_SHARE_DESTINATION": "share",
        "PROJECT_NAME": package,
    }


def install_rules(package_dir: Path, package: str) -> list[InstallRule]:
    """The FILES/PROGRAMS/DIRECTORY install() calls of a package (TARGETS, CODE and SCRIPT skipped)."""
    cmake = package_dir / "CMakeLists.txt"
    try:
        text = cmake.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    text = _COMMENT.sub(lambda m: " " * len(m.group(0)), text)
    variables = destinations(package)
    rules = []
    for match in _INSTALL.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        tokens = [_expand(t.strip("\"'"), variables) for t in match.group(1).split()]
        if not tokens or tokens[0] not in ("FILES", "PROGRAMS", "DIRECTORY"):
            continue
        items: list[str] = []
        destination = ""
        patterns: list[str] = []
        excludes: list[str] = []
        mode = "items"
        for i, token in enumerate(tokens[1:], 1):
            if token in _KEYWORDS:
                if token == "EXCLUDE" and patterns:
                    excludes.append(patterns.pop())
                mode = token
                continue
            if mode == "items":
                items.append(token)
            elif mode == "DESTINATION" and not destination:
                destination = token
            elif mode == "PATTERN" and tokens[i - 1] == "PATTERN":
                patterns.append(token)
        if not destination:
            raise PackageError(f"{cmake}:{line}: install({tokens[0]} ...) given no DESTINATION")
        rules.append(
            InstallRule(
                tokens[0],
                tuple(items),
                destination,
                tuple(patterns),
                tuple(excludes),
                "FILES_MATCHING" in tokens,
                "OPTIONAL" in tokens,
                line,
            )
        )
    return rules


def _expand(token: str, variables: Mapping[str, str]) -> str:
    return re.sub(r"\$\{([A-Za-z0-9_]+)\}", lambda m: variables.get(m.group(1), m.group(0)), token)


class _Installer:
    """Copies into the prefix, printing CMake's ``-- Installing:`` / ``-- Up-to-date:`` lines."""

    def __init__(self, prefix: Path, log: Callable[[str], None]) -> None:
        self.prefix = prefix
        self.log = log
        self.count = 0

    def copy(self, source: Path, target: Path, executable: bool | None = False) -> None:
        """Copy one file; ``executable`` None keeps the source's execute bit."""
        if executable is None:
            executable = os.access(source, os.X_OK)
        self._put(target, source.read_bytes(), executable)

    def write(self, target: Path, text: str, executable: bool = False) -> None:
        self._put(target, text.encode("utf-8"), executable)

    def _put(self, target: Path, data: bytes, executable: bool) -> None:
        self.count += 1
        try:
            same = target.read_bytes() == data
        except OSError:
            same = False
        if same:
            self.log(f"-- Up-to-date: {target}")
        else:
            target.parent.mkdir(parents=True, exist_ok=True)
            tmp = target.with_name(target.name + ".tmp")
            tmp.write_bytes(data)
            os.replace(tmp, target)
            self.log(f"-- Installing: {target}")
        if executable:
            target.chmod(target.stat().st_mode | 0o755)


def install_workspace(
    ws: Workspace, prefix: Path, env: Mapping[str, str], log: Callable[[str], None] = print
) -> int:
    """Install every package of a built workspace (``ws.load()`` done) under ``prefix``; the number
    of files installed."""
    out = _Installer(prefix, log)
    log(f'-- Install configuration: "" (prefix {prefix})')
    for pkg in ws.ordered():
        _install_package(pkg, out)
        if (pkg.path / "launch").is_dir() and not any(
            r.kind == "DIRECTORY" and any(Path(i).parts[-1:] == ("launch",) for i in r.items)
            for r in install_rules(pkg.path, pkg.name)
        ):
            log(
                f"-- {pkg.name}: launch/ is not installed: no install(DIRECTORY launch DESTINATION "
                "${CATKIN_PACKAGE_SHARE_DESTINATION}) in its CMakeLists.txt (as with catkin)"
            )
    dist = prefix / "lib" / "python3" / "dist-packages"
    for pkg in ws.ordered():
        _install_messages(pkg, dist, out)
        # regenerated rather than copied from devel/, whose <pkg>/__init__.py relays to the sources
        if cfg_gen.generate(pkg, dist, out) and not (dist / pkg.name / "__init__.py").exists():
            out.write(dist / pkg.name / "__init__.py", "")
    space = WorkspaceEnv(source=prefix / "share", devel=prefix)
    # a shell that sourced this install space before lists it too: it is no underlay of itself
    underlays = [u for u in underlay_workspaces(ws.devel, env) if u.devel.resolve() != prefix.resolve()]
    out.write(prefix / "setup.sh", render_setup_sh(space, underlays))
    out.write(prefix / "setup.bash", render_setup_bash(space))
    out.write(prefix / "setup.zsh", render_setup_zsh(space))
    for shell in ("sh", "bash", "zsh"):
        out.write(prefix / f"local_setup.{shell}", f'. "{prefix / f"setup.{shell}"}"\n')
    out.write(prefix / MARKER, json.dumps({"source": str(prefix / "share"), "devel": str(prefix)}) + "\n")
    return out.count


def _install_package(pkg: PackageManifest, out: _Installer) -> None:
    share = out.prefix / "share" / pkg.name
    out.copy(pkg.path / MANIFEST, share / MANIFEST)
    hints = read_cmake_hints(pkg.path)
    for program, destination in hints.install_programs:
        script = pkg.path / program
        if not script.is_file():
            raise PackageError(hints.missing_program(pkg.path, program))
        out.copy(script, out.prefix / destination.format(pkg=pkg.name) / script.name, executable=True)
    if hints.python_setup and (pkg.path / "setup.py").is_file():
        dist = out.prefix / "lib" / "python3" / "dist-packages"
        for module, source in python_packages(pkg.path).items():
            for path in sorted(source.glob("*")):  # setup.py lists subpackages itself
                if path.is_file() and path.suffix != ".pyc":
                    out.copy(path, dist.joinpath(*module.split(".")) / path.name)
    for rule in install_rules(pkg.path, pkg.name):
        _apply(rule, pkg, out)


def _apply(rule: InstallRule, pkg: PackageManifest, out: _Installer) -> None:
    target_dir = Path(rule.destination)
    if not target_dir.is_absolute():
        target_dir = out.prefix / target_dir
    where = f"{pkg.path / 'CMakeLists.txt'}:{rule.line}"
    for item in rule.items:
        source = pkg.path / item
        if rule.kind == "DIRECTORY":
            if not source.is_dir():
                if rule.optional:
                    continue
                raise PackageError(f"{where}: install(DIRECTORY {item}) names a missing directory")
            base = target_dir if item.endswith("/") else target_dir / source.name
            for path in sorted(source.rglob("*")):
                if path.is_file() and _wanted(path, rule):
                    out.copy(path, base / path.relative_to(source), executable=None)
            continue
        if not source.is_file():
            if rule.optional:
                continue
            raise PackageError(f"{where}: install({rule.kind} {item}) names a missing file")
        out.copy(source, target_dir / source.name, executable=rule.kind == "PROGRAMS")


def _wanted(path: Path, rule: InstallRule) -> bool:
    if any(fnmatch.fnmatch(path.name, p) for p in rule.excludes):
        return False
    if rule.files_matching:
        return any(fnmatch.fnmatch(path.name, p) for p in rule.patterns)
    return True


def _install_messages(pkg: PackageManifest, dist: Path, out: _Installer) -> None:
    """share/<pkg>/{msg,srv,action}/ and the message modules in dist-packages/<pkg>/."""
    kinds = [k for k in ("msg", "srv", "action") if sorted((pkg.path / k).glob(f"*.{k}"))]
    for kind in kinds:
        for path in sorted((pkg.path / kind).glob(f"*.{kind}")):
            out.copy(path, out.prefix / "share" / pkg.name / kind / path.name)
    if not kinds:
        return
    init = dist / pkg.name / "__init__.py"
    if not init.exists():
        out.write(
            init, "# Generated by ninjemys catkin_make: message/service modules live in msg/ and srv/.\n"
        )
    if "msg" in kinds or "action" in kinds:
        out.write(dist / pkg.name / "msg" / "__init__.py", STUB)
    if "srv" in kinds:
        out.write(dist / pkg.name / "srv" / "__init__.py", STUB)


__all__ = ["InstallRule", "destinations", "install_rules", "install_workspace"]
