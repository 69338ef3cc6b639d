"""C++ sides for the message packages ninjemys ships, where the machine has none.

A C++ node finds a message package through catkin's CMake (``find_package(catkin REQUIRED
COMPONENTS control_msgs)`` reads ``share/control_msgs/cmake/control_msgsConfig.cmake`` under a
prefix) and its headers on the include path (``#include <control_msgs/JointControllerState.h>``;
on a ROS 1 install every installed package's headers are in ``/opt/ros/noetic/include``, so nodes
include headers of packages they never declared, and real course code does). Debian ships the
C++ side of some message packages (``libstd-msgs-dev`` ...), of none of those that only ninjemys
provides (control_msgs, gazebo_msgs, fiducial_msgs, rosserial_msgs, ...).

:func:`write_prefix` makes a prefix (by default ``build/ninjemys_cpp/shipped`` of the workspace)
that has, for each shipped interface package without a C++ side here: the headers
(:mod:`ninjemys.packages.gencpp`), the definitions (actions expanded into their seven messages, as
catkin installs them: genmsg reads them when a workspace message uses one of these types), a
package config with genmsg's ``-msg-paths.cmake``, and a ``.catkin`` marker so catkin's CMake
treats the prefix as a workspace it overlays. The C++ build puts the prefix on CMAKE_PREFIX_PATH
and its ``include`` on every target's include path, as a ROS install does. Files are rewritten only
when their content changes, so a rebuild recompiles nothing.

The same prefix carries the shipped packages whose C++ side is only CMake functions (roslint's
``roslint_cpp()`` & co, :func:`cmake_only_packages`), so ``find_package(catkin REQUIRED COMPONENTS
roscpp roslint)`` configures as on a ROS 1 install.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.idl import loader, search
from ninjemys.idl.md5 import compute_md5, compute_srv_md5
from ninjemys.idl.parser import action_message_texts, read_definition
from ninjemys.idl.spec import MsgSpec
from ninjemys.packages.gencpp import message_header, service_header

#: packages whose C++ side is more than message headers, so a config of ours would mislead CMake:
#: roscpp (no toolchain without it), and those whose config brings CMake macros
#: (actionlib_msgs' add_action_files, dynamic_reconfigure's generate_dynamic_reconfigure_options):
#: without their real C++ side, CMake names them as missing, and catkin_make names the targets that
#: need them as not built. Library packages without macros (tf, actionlib) get their messages'
#: headers: a node on their library misses its header, and is named as not built the same way.
_NEVER = frozenset({"roscpp", "actionlib_msgs", "dynamic_reconfigure"})
#: prefixes where an installed C++ side of a package is looked for, besides CMAKE_PREFIX_PATH
_SYSTEM_PREFIXES = (Path("/usr"), Path("/usr/local"))
_OPT_ROS = Path("/opt/ros")
#: bumped when the generated files change shape, so existing prefixes are rewritten
GENERATOR_VERSION = "1"


@dataclass
class CppPrefix:
    """What :func:`write_prefix` made: the prefix and the packages it holds headers for."""

    root: Path
    packages: list[str] = field(default_factory=list)
    written: list[Path] = field(default_factory=list)

    @property
    def include(self) -> Path:
        return self.root / "include"


def installed_prefixes(env: Mapping[str, str]) -> list[Path]:
    """Where another C++ side of a package may be installed: CMAKE_PREFIX_PATH entries, /usr,
    /usr/local and ROS 1 binary installs under /opt/ros."""
    found = [Path(p) for p in env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
    found += list(_SYSTEM_PREFIXES)
    if _OPT_ROS.is_dir():
        found += sorted(p for p in _OPT_ROS.iterdir() if p.is_dir())
    return found


def has_cpp_side(package: str, prefixes: Iterable[Path]) -> bool:
    """True when some prefix has the package's CMake config (Debian's lib<pkg>-dev, a ROS install,
    a sourced workspace that built it): ``share/<pkg>/cmake`` for message packages, ``lib/cmake``
    or Debian's ``lib/<triplet>/cmake`` for libraries (actionlib, dynamic_reconfigure)."""
    config = f"{package}Config.cmake"
    for prefix in prefixes:
        if (prefix / "share" / package / "cmake" / config).is_file():
            return True
        if (prefix / "lib" / "cmake" / package / config).is_file():
            return True
        if any(prefix.glob(f"lib/*/cmake/{package}/{config}")):
            return True
    return False


def shipped_interface_packages() -> list[str]:
    """Every interface package ninjemys ships (a ``package.xml`` under ``ninjemys/interfaces``)."""
    root = Path(search.SHIPPED_ROOT)
    return sorted(p.name for p in root.iterdir() if (p / "package.xml").is_file())


def cmake_only_packages() -> dict[str, Path]:
    """Shipped packages whose whole C++ side is CMake code of ours (roslint's functions): each has
    ``cmake/<name>Config.cmake`` in its directory under ``ninjemys/packages/share``; by name."""
    root = Path(__file__).resolve().parent / "share"
    return {
        p.name: p
        for p in sorted(root.iterdir())
        if (p / "cmake" / f"{p.name}Config.cmake").is_file() and (p / "package.xml").is_file()
    }


def packages_without_cpp_side(env: Mapping[str, str], exclude: Iterable[str] = ()) -> list[str]:
    """The shipped interface packages (and CMake-only packages, :func:`cmake_only_packages`) that
    need ninjemys' C++ side on this machine: those no prefix provides, except the ones in
    ``exclude`` (packages of the workspace being built)."""
    prefixes = installed_prefixes(env)
    skip = set(exclude) | _NEVER
    names = [*shipped_interface_packages(), *cmake_only_packages()]
    return [p for p in names if p not in skip and not has_cpp_side(p, prefixes)]


class _Files:
    """Writes files only when their content changes; remembers what it wrote and what it kept."""

    def __init__(self, prefix: CppPrefix) -> None:
        self.prefix = prefix
        self.kept: set[Path] = set()

    def write(self, path: Path, content: str) -> None:
        self.kept.add(path)
        try:
            if path.read_text(encoding="utf-8") == content:
                return
        except OSError:
            pass
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(content, encoding="utf-8")
        os.replace(tmp, path)
        self.prefix.written.append(path)


def _version(package_dir: Path) -> str:
    match = re.search(r"<version>\s*([^<\s]+)\s*</version>", (package_dir / "package.xml").read_text("utf-8"))
    return match.group(1) if match else "0.0.0"


def _config(package: str, depends: list[str], exported: list[str]) -> str:
    dep_var = f"_ninjemys_{package}_dep"
    return f"""\
# {package}: C++ message headers made by ninjemys' catkin_make (this machine has no other C++ side
# of {package}). Read by find_package({package}) and catkin's COMPONENTS; the same variables as the
# config catkin writes for a message package.
if({package}_CONFIG_INCLUDED)
  return()
endif()
set({package}_CONFIG_INCLUDED TRUE)
set({package}_FOUND_CATKIN_PROJECT TRUE)
get_filename_component({package}_PREFIX "${{CMAKE_CURRENT_LIST_DIR}}/../../.." ABSOLUTE)
set({package}_INCLUDE_DIRS "${{{package}_PREFIX}}/include")
set({package}_LIBRARIES "")
set({package}_LIBRARY_DIRS "")
set({package}_EXPORTED_TARGETS "{";".join(exported)}")
foreach(_target ${{{package}_EXPORTED_TARGETS}})
  if(NOT TARGET ${{_target}})
    add_custom_target(${{_target}})
  endif()
endforeach()
foreach({dep_var} {" ".join(["message_runtime", *depends])})
  if(NOT ${{{dep_var}}}_FOUND)
    find_package(${{{dep_var}}} REQUIRED NO_MODULE)
  endif()
  foreach(_dir ${{${{{dep_var}}}_INCLUDE_DIRS}})
    list(FIND {package}_INCLUDE_DIRS ${{_dir}} _index)
    if(_index EQUAL -1)
      list(APPEND {package}_INCLUDE_DIRS ${{_dir}})
    endif()
  endforeach()
  list(APPEND {package}_LIBRARIES ${{${{{dep_var}}}_LIBRARIES}})
  list(APPEND {package}_LIBRARY_DIRS ${{${{{dep_var}}}_LIBRARY_DIRS}})
  list(APPEND {package}_EXPORTED_TARGETS ${{${{{dep_var}}}_EXPORTED_TARGETS}})
endforeach()
include(${{CMAKE_CURRENT_LIST_DIR}}/{package}-msg-paths.cmake)
include(${{CMAKE_CURRENT_LIST_DIR}}/{package}-msg-extras.cmake)
"""


def _config_version(version: str) -> str:
    return f"""\
# {version}: any requested version up to this one is compatible (catkin's rule)
set(PACKAGE_VERSION "{version}")
set(PACKAGE_VERSION_EXACT False)
set(PACKAGE_VERSION_COMPATIBLE False)
if("${{PACKAGE_FIND_VERSION}}" VERSION_EQUAL "${{PACKAGE_VERSION}}")
  set(PACKAGE_VERSION_EXACT True)
  set(PACKAGE_VERSION_COMPATIBLE True)
endif()
if("${{PACKAGE_FIND_VERSION}}" VERSION_LESS "${{PACKAGE_VERSION}}")
  set(PACKAGE_VERSION_COMPATIBLE True)
endif()
"""


def _write_package(package: str, files: _Files, root: Path) -> None:
    pkg = search.find_package(package)
    source = Path(pkg.path)
    share = root / "share" / package
    include = root / "include" / package
    files.write(share / "package.xml", (source / "package.xml").read_text(encoding="utf-8"))
    md5s: dict[str, str] = {}
    messages: dict[str, MsgSpec] = {}
    msg_files: list[str] = []
    srv_files: list[str] = []
    depends: dict[str, None] = {}
    for short, path in pkg.definitions("msg").items():
        files.write(share / "msg" / f"{short}.msg", read_definition(path))
        messages[short] = loader.get_message_spec(f"{package}/{short}")
        msg_files.append(f"msg/{short}.msg")
    for short, path in pkg.definitions("action").items():
        text = read_definition(path)
        files.write(share / "action" / f"{short}.action", text)
        for name, body in action_message_texts(text, f"{package}/{short}", path).items():
            files.write(share / "msg" / f"{name}.msg", body)
            messages[name] = loader.get_message_spec(f"{package}/{name}")
            msg_files.append(f"msg/{name}.msg")
    for short, spec in sorted(messages.items()):
        md5 = compute_md5(spec, loader.get_message_spec, md5s)
        text = loader.get_full_text(spec.full_name)
        where = f"{package}/msg/{short}.msg"
        files.write(include / f"{short}.h", message_header(spec, loader.get_message_spec, md5, text, where))
        depends.update((d.split("/")[0], None) for d in spec.dependencies)
    for short, path in pkg.definitions("srv").items():
        files.write(share / "srv" / f"{short}.srv", read_definition(path))
        srv = loader.get_service_spec(f"{package}/{short}")
        srv_files.append(f"srv/{short}.srv")
        where = f"{package}/srv/{short}.srv"
        for part in (srv.request, srv.response):
            md5 = compute_md5(part, loader.get_message_spec, md5s)
            text = loader.get_full_text(part.full_name)
            header = message_header(part, loader.get_message_spec, md5, text, where)
            files.write(include / f"{part.short_name}.h", header)
            depends.update((d.split("/")[0], None) for d in part.dependencies)
        srv_md5 = compute_srv_md5(srv, loader.get_message_spec, md5s)
        files.write(include / f"{short}.h", service_header(srv, srv_md5, where))
    deps = sorted(d for d in depends if d != package)
    exported = [f"{package}_generate_messages_{lang}" for lang in ("cpp", "eus", "lisp", "nodejs", "py")]
    cmake = share / "cmake"
    files.write(cmake / f"{package}Config.cmake", _config(package, deps, exported))
    files.write(cmake / f"{package}Config-version.cmake", _config_version(_version(source)))
    files.write(
        cmake / f"{package}-msg-paths.cmake",
        f'set({package}_MSG_INCLUDE_DIRS "{share / "msg"}")\nset({package}_MSG_DEPENDENCIES {";".join(deps)})\n',
    )
    files.write(
        cmake / f"{package}-msg-extras.cmake",
        f'set({package}_MESSAGE_FILES "{";".join(sorted(msg_files))}")\n'
        f'set({package}_SERVICE_FILES "{";".join(sorted(srv_files))}")\n',
    )


def _copy_cmake_package(source: Path, files: _Files, root: Path) -> None:
    """A CMake-only package into the prefix: its package.xml and cmake files, with the Python that
    runs ninjemys written in (the commands its functions add run ninjemys' modules)."""
    share = root / "share" / source.name
    files.write(share / "package.xml", (source / "package.xml").read_text(encoding="utf-8"))
    for path in sorted((source / "cmake").glob("*.cmake")):
        text = path.read_text(encoding="utf-8").replace("@NINJEMYS_PYTHON@", sys.executable)
        files.write(share / "cmake" / path.name, text)


def write_prefix(root: Path, packages: Iterable[str]) -> CppPrefix:
    """Write (or bring up to date) the prefix for ``packages``; files of packages no longer asked
    for are removed. Raises DefinitionError / TypeNotFoundError for a broken shipped definition."""
    prefix = CppPrefix(root, sorted(set(packages)))
    files = _Files(prefix)
    files.write(root / ".catkin", "")
    files.write(
        root / "ninjemys_cpp_msgs.txt", f"generator {GENERATOR_VERSION}\n" + "\n".join(prefix.packages) + "\n"
    )
    cmake_only = cmake_only_packages()
    for package in prefix.packages:
        if package in cmake_only:
            _copy_cmake_package(cmake_only[package], files, root)
        else:
            _write_package(package, files, root)
    for directory in (root / "include", root / "share"):
        if not directory.is_dir():
            continue
        for path in sorted(directory.rglob("*"), reverse=True):
            if path.is_file() and path not in files.kept:
                path.unlink()
            elif path.is_dir() and not any(path.iterdir()):
                path.rmdir()
    return prefix


__all__ = [
    "CppPrefix",
    "GENERATOR_VERSION",
    "cmake_only_packages",
    "has_cpp_side",
    "installed_prefixes",
    "packages_without_cpp_side",
    "shipped_interface_packages",
    "write_prefix",
]
