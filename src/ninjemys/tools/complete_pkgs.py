"""Package, interface and file names for shell completion, found with nothing but ``os``.

Completion runs on every Tab press, so this module walks the same roots as
:mod:`ninjemys.packages.discovery` (ROS_PACKAGE_PATH, then the packages shipped inside ninjemys) and
:mod:`ninjemys.idl.search` (plus ``share/<pkg>`` under CMAKE_PREFIX_PATH for interfaces) without
importing them: their dataclass/pathlib/XML imports alone cost more than the whole answer should.
The crawl rules are rospkg's (a directory with a package.xml is a package and is not descended into;
hidden directories and those marked CATKIN_IGNORE, COLCON_IGNORE or rospack_nosubdirs are skipped),
and tests check that the names found here equal theirs.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

_MANIFEST = "package.xml"
_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "rospack_nosubdirs")
_MAX_DEPTH = 12
#: directories never worth walking into when listing a package's files
_SKIP_DIRS = frozenset({"__pycache__", "build", "node_modules"})
#: a package with a huge tree must not stall the shell: stop listing after this many files
_MAX_FILES = 5000

_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def shipped_roots() -> list[str]:
    """Package roots inside ninjemys: the interface packages, then the executable-only ones."""
    roots = [os.path.join(_ROOT, "interfaces"), os.path.join(_ROOT, "packages", "share")]
    return [r for r in roots if os.path.isdir(r)]


def package_path_roots() -> list[str]:
    """Existing ROS_PACKAGE_PATH entries, in order."""
    roots: list[str] = []
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry and os.path.isdir(entry) and os.path.realpath(entry) not in roots:
            roots.append(os.path.realpath(entry))
    return roots


def manifest_name(package_dir: str) -> str:
    """The ``<name>`` of a package.xml (the directory name if the file has none)."""
    try:
        with open(os.path.join(package_dir, _MANIFEST), encoding="utf-8", errors="replace") as f:
            text = f.read(65536)
    except OSError:
        return os.path.basename(package_dir)
    start = text.find("<name>")
    end = text.find("</name>", start)
    if start < 0 or end < 0:
        return os.path.basename(package_dir)
    return text[start + len("<name>") : end].strip() or os.path.basename(package_dir)


def crawl(root: str) -> Iterator[str]:
    """Every package directory under ``root`` (``root`` itself if it is one)."""
    stack = [(root, 0)]
    while stack:
        directory, depth = stack.pop()
        if os.path.isfile(os.path.join(directory, _MANIFEST)):
            yield directory
            continue
        if depth >= _MAX_DEPTH or any(os.path.exists(os.path.join(directory, m)) for m in _IGNORE_MARKERS):
            continue
        try:
            with os.scandir(directory) as entries:
                children = sorted(
                    (e.path for e in entries if not e.name.startswith((".", "__")) and e.is_dir()),
                    reverse=True,
                )
        except OSError:
            continue
        stack.extend((child, depth + 1) for child in children)


def packages() -> dict[str, str]:
    """Package name -> directory, first root wins (a sourced workspace overlays the shipped ones)."""
    found: dict[str, str] = {}
    for root in package_path_roots() + shipped_roots():
        for package_dir in crawl(root):
            found.setdefault(manifest_name(package_dir), package_dir)
    return found


def interface_packages() -> dict[str, list[str]]:
    """Package name -> every directory that may hold its msg/ and srv/ (shipped, workspaces, installs)."""
    found: dict[str, list[str]] = {}
    for name, directory in packages().items():
        found.setdefault(name, []).append(directory)
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        share = os.path.join(prefix, "share") if prefix else ""
        if not share or not os.path.isdir(share):
            continue
        try:
            with os.scandir(share) as entries:
                for entry in entries:
                    if entry.is_dir() and os.path.isfile(os.path.join(entry.path, _MANIFEST)):
                        found.setdefault(entry.name, []).append(entry.path)
        except OSError:
            continue
    return found


def interface_types(kind: str) -> list[str]:
    """Every ``pkg/Type`` of ``kind`` ("msg" or "srv") visible to the message loader, sorted."""
    types: set[str] = set()
    suffix = "." + kind
    for name, directories in interface_packages().items():
        for directory in directories:
            try:
                with os.scandir(os.path.join(directory, kind)) as entries:
                    types.update(
                        f"{name}/{e.name[: -len(suffix)]}" for e in entries if e.name.endswith(suffix)
                    )
            except OSError:
                continue
    return sorted(types)


def package_files(package_dir: str) -> Iterator[tuple[str, str]]:
    """(relative path, absolute path) of the files in a package, hidden and build trees skipped."""
    count = 0
    for dirpath, dirnames, filenames in os.walk(package_dir, followlinks=True):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in _SKIP_DIRS)
        for filename in sorted(filenames):
            if filename.startswith(".") or filename.endswith(".pyc"):
                continue
            path = os.path.join(dirpath, filename)
            yield os.path.relpath(path, package_dir), path
            count += 1
            if count >= _MAX_FILES:
                return


def package_subpaths(spec: str, files: bool) -> list[str]:
    """Completions of ``pkg/sub/dir`` for roscd (directories) and rosls (directories and files).

    Without a slash the candidates are package names; with one, the entries of the directory the
    spec names, directories ending in ``/`` so the user can keep descending.
    """
    if "/" not in spec:
        return sorted(name for name in packages() if name.startswith(spec))
    package, _, rest = spec.partition("/")
    base = packages().get(package)
    if base is None:
        return []
    head, _, leaf = rest.rpartition("/")
    directory = os.path.join(base, head) if head else base
    result = []
    try:
        with os.scandir(directory) as entries:
            for entry in entries:
                if not entry.name.startswith(leaf) or (
                    entry.name.startswith(".") and not leaf.startswith(".")
                ):
                    continue
                shown = f"{package}/{head + '/' if head else ''}{entry.name}"
                if entry.is_dir():
                    result.append(shown + "/")
                elif files:
                    result.append(shown)
    except OSError:
        return []
    return sorted(result)


def executables(package: str) -> list[str]:
    """What ``rosrun PACKAGE <Tab>`` offers: executable files of the package and its devel/lib
    directories, plus the nodes ninjemys ships as Python modules for it."""
    names: set[str] = set()
    base = packages().get(package)
    if base is not None:
        for rel, path in package_files(base):
            if os.access(path, os.X_OK):
                names.add(os.path.basename(rel))
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(os.pathsep):
        lib = os.path.join(prefix, "lib", package) if prefix else ""
        if lib and os.path.isdir(lib):
            try:
                with os.scandir(lib) as entries:
                    names.update(e.name for e in entries if e.is_file() and os.access(e.path, os.X_OK))
            except OSError:
                continue
    from ninjemys.packages.shipped import SHIPPED  # only rosrun needs the table of shipped nodes

    names.update(SHIPPED.get(package, {}))
    return sorted(names)


def launch_files(package: str) -> list[str]:
    """Launch files (``*.launch``, ``*.test``, ``*.xml`` under a ``launch`` directory) of a package."""
    base = packages().get(package)
    if base is None:
        return []
    found = set()
    for rel, _ in package_files(base):
        name = os.path.basename(rel)
        if name.endswith((".launch", ".test")) or (
            name.endswith(".xml") and "launch" in rel.split(os.sep)[:-1]
        ):
            found.add(name)
    return sorted(found)


def find_package_file(package: str, filename: str) -> str | None:
    """The first file called ``filename`` inside ``package`` (how roslaunch finds ``pkg file``)."""
    base = packages().get(package)
    if base is None:
        return None
    for rel, path in package_files(base):
        if os.path.basename(rel) == filename:
            return path
    return None


def launch_args(path: str) -> list[str]:
    """``name:=`` for every ``<arg>`` of a launch file that a caller may set (no fixed ``value``)."""
    import xml.etree.ElementTree as ET  # noqa: N817 - only this rare completion parses XML

    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        return []
    names: list[str] = []
    pending = [root]
    while pending:  # <arg>s of the file and its <group>s; those under <include>/<node> are not its own
        element = pending.pop(0)
        for child in element:
            if child.tag == "group":
                pending.append(child)
            elif child.tag == "arg":
                name = child.get("name")
                if name and "value" not in child.attrib and name + ":=" not in names:
                    names.append(name + ":=")
    return names
