"""Build a workspace's C++ packages through real CMake with catkin's own macros, where a toolchain exists.

ninjemys' catkin_make writes Python relays itself, but compiling roscpp nodes needs what ROS 1 has:
a C++ compiler, CMake, catkin's CMake (``toplevel.cmake``) and roscpp's development files (Debian's
``catkin``, ``g++``, ``libroscpp-dev``). When they are all present, the packages that declare C++
targets, with the workspace packages they depend on (so their messages get C++ headers too), are
configured and built by catkin itself in ``build/ninjemys_cpp`` (its own devel space, so it never
overwrites ours), and each built program is linked into ``devel/lib/<pkg>/`` where rosrun and
roslaunch look. Without the toolchain, :func:`find_toolchain` says what is missing and the targets
are named as not built. ``NINJEMYS_CATKIN_CPP=0`` asks for the Python-only build on purpose.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.cpp_msgs import CppPrefix
from ninjemys.packages.manifest import PackageManifest

#: where catkin's top-level CMake file lives: Debian's ``catkin``, then ROS 1 binary installs
_TOPLEVEL = (Path("/usr/share/catkin/cmake/toplevel.cmake"),)
_ROSCPP_CONFIGS = ("/usr/lib/*/cmake/roscpp/roscppConfig.cmake", "/usr/share/roscpp/cmake/roscppConfig.cmake")
_OPT_ROS = Path("/opt/ros")


@dataclass(frozen=True)
class Toolchain:
    """The programs and catkin files a C++ build needs."""

    cmake: str
    compiler: str
    toplevel: Path
    python: str


def _toplevel_candidates() -> list[Path]:
    found = list(_TOPLEVEL)
    if _OPT_ROS.is_dir():
        found += sorted(_OPT_ROS.glob("*/share/catkin/cmake/toplevel.cmake"))
    return found


def _roscpp_found() -> bool:
    for pattern in _ROSCPP_CONFIGS:
        root = Path("/")
        if any(root.glob(pattern.lstrip("/"))):
            return True
    return _OPT_ROS.is_dir() and any(_OPT_ROS.glob("*/share/roscpp/cmake/roscppConfig.cmake"))


def find_toolchain(env: Mapping[str, str]) -> tuple[Toolchain | None, str]:
    """The toolchain, or None and the reason (shown with the targets it leaves unbuilt)."""
    if env.get("NINJEMYS_CATKIN_CPP", "1") == "0":
        return None, "NINJEMYS_CATKIN_CPP=0 asks for the Python-only build"
    path = env.get("PATH", os.defpath)
    cmake = shutil.which("cmake", path=path)
    compiler = shutil.which("c++", path=path) or shutil.which("g++", path=path)
    toplevel = next((p for p in _toplevel_candidates() if p.is_file()), None)
    missing = [
        what
        for what, ok in (
            ("cmake", cmake),
            ("a C++ compiler (g++)", compiler),
            ("catkin's CMake (Debian package catkin)", toplevel),
            ("roscpp's development files (Debian package libroscpp-dev)", _roscpp_found()),
        )
        if not ok
    ]
    if missing:
        return None, "no " + ", no ".join(missing)
    # catkin's CMake runs catkin_pkg, which lives with the system Python, not necessarily ours
    python = (
        "/usr/bin/python3" if Path("/usr/bin/python3").is_file() else (shutil.which("python3") or "python3")
    )
    assert cmake and compiler and toplevel
    return Toolchain(cmake, compiler, toplevel, python), ""


_BOOST_VERSION = Path("/usr/include/boost/version.hpp")


def noetic_compat_flags(version_header: Path = _BOOST_VERSION) -> str:
    """Compiler flags that give newer Boost (1.73+, as in Debian 12) the global ``_1``, ``_2`` ...
    that Noetic's Boost 1.71 had: roscpp's headers include ``<boost/bind/bind.hpp>``, and with Boost
    1.73+ that no longer brings the placeholders into the global namespace, so the tutorials'
    ``boost::bind(&Server::executeCB, this, _1)`` stops compiling. Force-including ``<boost/bind.hpp>``
    with ``BOOST_BIND_GLOBAL_PLACEHOLDERS`` is Boost's own way back to the old names (no warning).
    Empty for Boost 1.72 and older, or when Boost is not installed."""
    try:
        text = version_header.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""
    match = re.search(r"#define\s+BOOST_VERSION\s+(\d+)", text)
    if match is None or int(match.group(1)) < 107300:
        return ""
    return "-DBOOST_BIND_GLOBAL_PLACEHOLDERS -include boost/bind.hpp"


def cpp_closure(packages: list[PackageManifest], wanted: set[str]) -> list[PackageManifest]:
    """The wanted packages and every workspace package they depend on, transitively."""
    by_name = {p.name: p for p in packages}
    todo = [n for n in wanted if n in by_name]
    chosen: set[str] = set()
    while todo:
        name = todo.pop()
        if name in chosen:
            continue
        chosen.add(name)
        manifest = by_name[name]
        deps = manifest.buildtool_depends + manifest.build_depends + manifest.build_export_depends
        todo += [d for d in deps + manifest.exec_depends if d in by_name and d not in chosen]
    return [p for p in packages if p.name in chosen]


def _link_sources(src: Path, packages: list[PackageManifest], toplevel: Path) -> None:
    """A source space of links to the chosen packages (re-made each run: the set may change)."""
    src.mkdir(parents=True, exist_ok=True)
    for entry in src.iterdir():
        if entry.is_symlink():
            entry.unlink()
    for pkg in packages:
        (src / pkg.name).symlink_to(pkg.path.resolve(), target_is_directory=True)
    (src / "CMakeLists.txt").symlink_to(toplevel)


def cmake_env(base: Mapping[str, str]) -> dict[str, str]:
    """The environment catkin's CMake runs in: the caller's, without ROS_DISTRO. A shell that
    sourced a ninjemys workspace has ``ROS_DISTRO=noetic``; catkin's configure step runs its env
    hooks to cache the environment, and Debian's ``1.ros_distro.sh`` hook then prints "ROS_DISTRO was
    set to 'noetic' before ..." on stdout, which catkin reads as a Python dict: the configure fails.
    The hook sets the distribution of the catkin in use itself, as in a fresh ROS 1 shell."""
    env = dict(base)
    env.pop("ROS_DISTRO", None)
    return env


def build_cpp(
    packages: list[PackageManifest],
    build_root: Path,
    install_prefix: Path,
    toolchain: Toolchain,
    log: Callable[[str], None],
    jobs: int = 0,
    messages: CppPrefix | None = None,
) -> dict[str, list[Path]]:
    """Configure and build the packages with catkin's CMake; the programs built, per package.

    ``messages`` is the prefix with the C++ side of ninjemys' own message packages
    (:mod:`ninjemys.packages.cpp_msgs`): it goes last on CMAKE_PREFIX_PATH (anything installed
    wins) and its headers on every target's include path, as ``/opt/ros/noetic/include`` is.
    Raises PackageError with CMake's or the compiler's output (as catkin_make prints it) on failure.
    """
    src = build_root / "src"
    build = build_root / "build"
    devel = build_root / "devel"
    _link_sources(src, packages, toolchain.toplevel)
    build.mkdir(parents=True, exist_ok=True)
    env = cmake_env(os.environ)
    extra: list[str] = []
    if messages is not None and messages.packages:
        paths = [p for p in env.get("CMAKE_PREFIX_PATH", "").split(os.pathsep) if p]
        env["CMAKE_PREFIX_PATH"] = os.pathsep.join([*paths, str(messages.root)])
        extra.append(f"-DCMAKE_CXX_STANDARD_INCLUDE_DIRECTORIES={messages.include}")
    configure = [
        toolchain.cmake,
        str(src),
        f"-DCATKIN_DEVEL_PREFIX={devel}",
        f"-DCMAKE_INSTALL_PREFIX={install_prefix}",
        f"-DPYTHON_EXECUTABLE={toolchain.python}",
        f"-DCMAKE_CXX_COMPILER={toolchain.compiler}",
        "-DCATKIN_ENABLE_TESTING=OFF",
        *extra,
    ]
    flags = noetic_compat_flags()
    if flags:
        configure.append(f"-DCMAKE_CXX_FLAGS={' '.join([env.get('CXXFLAGS', ''), flags]).strip()}")
    log(f"-- ~~  C++ packages through catkin's CMake: {' '.join(p.name for p in packages)}")
    _run(configure, build, env, 'Invoking "cmake" failed', log)
    jobs = jobs or max(1, os.cpu_count() or 1)
    _run(["make", f"-j{jobs}"], build, env, f'Invoking "make -j{jobs}" failed', log)
    built: dict[str, list[Path]] = {}
    for pkg in packages:
        directory = devel / "lib" / pkg.name
        if directory.is_dir():
            programs = [
                p
                for p in sorted(directory.iterdir())
                if p.is_file() and os.access(p, os.X_OK) and not p.suffix
            ]
            if programs:
                built[pkg.name] = programs
    return built


def install_cpp(build: Path, log: Callable[[str], None], jobs: int = 0) -> int:
    """``make install`` in catkin's build tree of the C++ packages (configured with the install
    prefix by :func:`build_cpp`): what ``install(TARGETS ...)`` names goes where catkin puts it
    (``lib/<pkg>/`` for ``${CATKIN_PACKAGE_BIN_DESTINATION}``, ``lib/`` for libraries, ``include/``),
    with catkin's CMake config files and RPATH handling, because it is catkin doing it. Run before
    ninjemys' own install, which then writes the setup scripts over catkin's. The number of files
    CMake installed or found up to date; raises PackageError with CMake's output on failure."""
    jobs = jobs or max(1, os.cpu_count() or 1)
    proc = subprocess.run(
        ["make", "install", f"-j{jobs}"],
        cwd=build,
        env=cmake_env(os.environ),
        capture_output=True,
        text=True,
        check=False,
    )
    if proc.returncode != 0:
        output = (proc.stdout + proc.stderr).rstrip()
        raise PackageError(f'{output}\nInvoking "make install -j{jobs}" failed')
    count = 0
    for line in proc.stdout.splitlines():
        if line.startswith(("-- Installing:", "-- Up-to-date:")):
            count += 1
            log(line)
        elif line.startswith("-- Set runtime path"):
            log(line)
    return count


#: genmsg's error when a dependency's .msg files are not where its CMake config says
_NO_MSG = re.compile(r"Cannot locate message \[(\w+)\] in package \[(\w+)\] with paths\s+\[\['([^']+)'\]\]")


_NO_CONFIG = re.compile(r'Could not find a package configuration file provided by "([^"]+)"')


_NO_HEADER = re.compile(r"fatal error: ([A-Za-z][A-Za-z0-9_]*)/[\w./]+\.h(?:pp)?: No such file or directory")


def missing_cpp_dependency(output: str) -> tuple[str, bool] | None:
    """(package, from_header) when the build stopped for want of a package's C++ side: its CMake
    config or the .msg files message generation reads (configure step), or one of its headers
    (``fatal error: control_msgs/JointControllerState.h: No such file``; ``from_header`` True: the
    caller checks it names a ROS package). None for any other failure (a compile error in the
    package's own code, a CMakeLists.txt mistake): those fail the build, as with catkin."""
    flat = " ".join(output.split())
    if 'Invoking "cmake" failed' in output:
        match = _NO_CONFIG.search(flat)
        if match is not None:
            return match.group(1), False
        match = _NO_MSG.search(flat)
        return (match.group(2), False) if match is not None else None
    match = _NO_HEADER.search(flat)
    return (match.group(1), True) if match is not None else None


def failing_package(output: str, packages: set[str]) -> str | None:
    """Which of ``packages`` the failure is in: the first ``<pkg>/CMakeLists.txt:<line>`` of CMake's
    call stack, or the first compiler diagnostic under ``src/<pkg>/`` of the C++ source space."""
    for pattern in (r"(?:^|\s)([A-Za-z][\w]*)/CMakeLists\.txt:\d+", r"ninjemys_cpp/src/([A-Za-z][\w]*)/"):
        for match in re.finditer(pattern, output, re.M):
            if match.group(1) in packages:
                return match.group(1)
    return None


def missing_definitions_hint(output: str) -> str:
    """One line for genmsg's "Cannot locate message" when the package's msg directory is absent:
    Debian ships a message package's CMake config (with its C++ headers) apart from its ``.msg``
    files, which catkin's C++ generation reads; ninjemys' own copies serve Python only. Empty when
    the error is another one."""
    match = _NO_MSG.search(" ".join(output.split()))
    if match is None or Path(match.group(3)).is_dir():
        return ""
    package = match.group(2)
    return (
        f"ninjemys: {match.group(3)} does not exist: {package}'s .msg files for C++ generation come with "
        f"Debian's package ros-{package.replace('_', '-')} (ROS 1 binary installs: ros-noetic-"
        f"{package.replace('_', '-')}); install it and run catkin_make again"
    )


def _run(cmd: list[str], cwd: Path, env: dict[str, str], failure: str, log: Callable[[str], None]) -> None:
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        output = (proc.stdout + proc.stderr).rstrip()
        hint = missing_definitions_hint(output)
        raise PackageError(f"{output}\n{failure}" + (f"\n\n{hint}" if hint else ""))
    for line in proc.stdout.splitlines():
        if line.startswith("[") and "Built target" in line:
            log(line)


__all__ = [
    "Toolchain",
    "build_cpp",
    "cmake_env",
    "cpp_closure",
    "failing_package",
    "find_toolchain",
    "install_cpp",
    "missing_cpp_dependency",
    "missing_definitions_hint",
    "noetic_compat_flags",
]
