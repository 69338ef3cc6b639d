"""package.xml (REP 127 / 140 / 149, formats 1-3) parsed into a plain dataclass.

Only what the tools need is kept: name, version, description, maintainers, license and the
dependency lists. Format 1's ``run_depend`` counts as an exec dependency; format 2+'s ``depend``
counts as build, export and exec dependency. Format 3 ``condition`` attributes are evaluated
against the environment (``$ROS_VERSION == 1`` and friends) like catkin_pkg does.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import PackageError

MANIFEST = "package.xml"

_DEP_TAGS = {
    "build_depend": ("build",),
    "buildtool_depend": ("buildtool",),
    "build_export_depend": ("build_export",),
    "exec_depend": ("exec",),
    "run_depend": ("build_export", "exec"),
    "depend": ("build", "build_export", "exec"),
    "test_depend": ("test",),
    "doc_depend": ("doc",),
}


@dataclass(frozen=True)
class PackageManifest:
    """One package.xml; ``path`` is the package directory (where package.xml lives)."""

    name: str
    path: Path
    version: str = ""
    format: int = 1
    description: str = ""
    maintainers: tuple[str, ...] = ()
    licenses: tuple[str, ...] = ()
    build_depends: tuple[str, ...] = ()
    buildtool_depends: tuple[str, ...] = ()
    build_export_depends: tuple[str, ...] = ()
    exec_depends: tuple[str, ...] = ()
    test_depends: tuple[str, ...] = ()
    doc_depends: tuple[str, ...] = ()
    exports: dict[str, str] = field(default_factory=dict, compare=False)

    @property
    def run_depends(self) -> tuple[str, ...]:
        """Everything needed at run time (exec + build_export), in declaration order, no repeats."""
        return tuple(dict.fromkeys(self.exec_depends + self.build_export_depends))

    @property
    def rospack_depends(self) -> tuple[str, ...]:
        """What ``rospack depends1`` lists: every dependency but the buildtool ones (catkin), as the
        tutorials show (``rospack depends1 beginner_tutorials``: roscpp rospy std_msgs)."""
        return tuple(d for d in self.all_depends if d not in self.buildtool_depends)

    @property
    def all_depends(self) -> tuple[str, ...]:
        """Every declared dependency except docs, in declaration order, no repeats."""
        return tuple(
            dict.fromkeys(
                self.buildtool_depends
                + self.build_depends
                + self.build_export_depends
                + self.exec_depends
                + self.test_depends
            )
        )


def _line_of(exc: ET.ParseError) -> int:
    return exc.position[0] if getattr(exc, "position", None) else 0


def _condition_holds(condition: str | None) -> bool:
    """Evaluate a REP 149 condition such as ``$ROS_VERSION == 1`` (ROS_VERSION defaults to 1 here)."""
    if not condition:
        return True
    env = {"ROS_VERSION": "1", "ROS_PYTHON_VERSION": "3", "ROS_DISTRO": "noetic"}
    env.update({k: v for k, v in os.environ.items() if k.startswith("ROS_")})

    def value(token: str) -> str:
        token = token.strip()
        if token.startswith("$"):
            return env.get(token[1:], "")
        return token.strip("'\"")

    for disjunct in re.split(r"\bor\b", condition):
        ok = True
        for conjunct in re.split(r"\band\b", disjunct):
            m = re.match(r"\s*(\S+)\s*(==|!=|>=|<=|>|<)\s*(\S+)\s*$", conjunct)
            if not m:
                raise PackageError(f"cannot evaluate package.xml condition {condition!r}")
            left, op, right = value(m.group(1)), m.group(2), value(m.group(3))
            ok = (
                ok
                and {
                    "==": left == right,
                    "!=": left != right,
                    ">=": left >= right,
                    "<=": left <= right,
                    ">": left > right,
                    "<": left < right,
                }[op]
            )
        if ok:
            return True
    return False


def parse_manifest(xml_path: str | Path) -> PackageManifest:
    """Parse one package.xml; malformed files raise PackageError naming ``file:line``."""
    xml_path = Path(xml_path)
    try:
        root = ET.parse(xml_path).getroot()
    except ET.ParseError as exc:
        raise PackageError(f"{xml_path}:{_line_of(exc)}: malformed package.xml: {exc.msg}") from None
    except OSError as exc:
        raise PackageError(f"{xml_path}: cannot read package.xml: {exc.strerror}") from None
    if root.tag != "package":
        raise PackageError(f"{xml_path}:1: root element must be <package>, not <{root.tag}>")
    fmt_text = root.get("format", "1")
    if fmt_text not in ("1", "2", "3"):
        raise PackageError(f"{xml_path}:1: unsupported package.xml format {fmt_text!r} (1, 2 or 3)")
    name_el = root.find("name")
    name = (name_el.text or "").strip() if name_el is not None else ""
    if not name:
        raise PackageError(f"{xml_path}: package.xml has no <name>")
    if not re.match(r"^[A-Za-z][A-Za-z0-9_]*$", name):
        raise PackageError(f"{xml_path}: invalid package name {name!r} (letters, digits and _ only)")
    deps: dict[str, list[str]] = {
        k: [] for k in ("build", "buildtool", "build_export", "exec", "test", "doc")
    }
    for el in root:
        kinds = _DEP_TAGS.get(el.tag)
        if kinds is None or not _condition_holds(el.get("condition")):
            continue
        dep = (el.text or "").strip()
        if not dep:
            raise PackageError(f"{xml_path}: empty <{el.tag}> in package {name}")
        for kind in kinds:
            if dep not in deps[kind]:
                deps[kind].append(dep)
    exports: dict[str, str] = {}
    export_el = root.find("export")
    if export_el is not None:
        for child in export_el:
            if not _condition_holds(child.get("condition")):
                continue  # e.g. <build_type condition="$ROS_VERSION == 2">ament_cmake</build_type>
            exports[child.tag] = (child.text or "").strip() or " ".join(
                f"{k}={v}" for k, v in child.attrib.items()
            )

    def texts(tag: str) -> tuple[str, ...]:
        return tuple((el.text or "").strip() for el in root.findall(tag))

    version = texts("version")
    description = root.find("description")
    return PackageManifest(
        name=name,
        path=xml_path.parent.resolve(),
        version=version[0] if version else "",
        format=int(fmt_text),
        description=" ".join("".join(description.itertext()).split()) if description is not None else "",
        maintainers=texts("maintainer"),
        licenses=texts("license"),
        build_depends=tuple(deps["build"]),
        buildtool_depends=tuple(deps["buildtool"]),
        build_export_depends=tuple(deps["build_export"]),
        exec_depends=tuple(deps["exec"]),
        test_depends=tuple(deps["test"]),
        doc_depends=tuple(deps["doc"]),
        exports=exports,
    )
