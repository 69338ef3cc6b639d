"""Where packages are found: ROS_PACKAGE_PATH (workspaces overlay), then ninjemys' shipped packages.

Order is precedence, as in rospkg: the first directory holding a package of a given name wins, so a
sourced workspace (whose ``src`` devel/setup.bash puts first on ROS_PACKAGE_PATH) overlays the
underlay. The underlay is ninjemys itself: the interface packages in ``ninjemys/interfaces`` and the
executable-only packages in ``ninjemys/packages/share`` (turtlesim, rospy_tutorials, ...).

Crawling follows rospkg: a directory with a package.xml is a package and is not descended into;
directories holding ``CATKIN_IGNORE`` or ``rospack_nosubdirs`` and hidden directories are skipped.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ninjemys.errors import PackageError
from ninjemys.packages.manifest import MANIFEST, PackageManifest, parse_manifest

_IGNORE_MARKERS = ("CATKIN_IGNORE", "COLCON_IGNORE", "rospack_nosubdirs")
_MAX_DEPTH = 12


def underlay_dirs() -> list[Path]:
    """The package roots shipped inside ninjemys, searched after ROS_PACKAGE_PATH."""
    root = Path(__file__).resolve().parent.parent
    return [p for p in (root / "interfaces", root / "packages" / "share") if p.is_dir()]


def package_path_dirs(env: Mapping[str, str] | None = None) -> list[Path]:
    """ROS_PACKAGE_PATH entries (existing ones, in order, without repeats)."""
    env = os.environ if env is None else env
    seen: dict[Path, None] = {}
    for entry in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry and Path(entry).is_dir():
            seen.setdefault(Path(entry).resolve(), None)
    return list(seen)


def crawl(root: Path) -> Iterator[Path]:
    """Every package directory under ``root`` (``root`` itself if it is one), in sorted order."""
    stack: list[tuple[Path, int]] = [(root, 0)]
    while stack:
        directory, depth = stack.pop()
        # the markers come first, as in catkin_pkg: CATKIN_IGNORE beside a package.xml hides it
        if any((directory / m).exists() for m in _IGNORE_MARKERS[:2]):
            continue
        if (directory / MANIFEST).is_file():
            yield directory
            continue
        if depth >= _MAX_DEPTH or (directory / _IGNORE_MARKERS[2]).exists():
            continue
        try:
            children = sorted(
                (c for c in directory.iterdir() if c.is_dir() and not c.name.startswith((".", "__"))),
                reverse=True,
            )
        except OSError:
            continue
        stack.extend((c, depth + 1) for c in children)


@dataclass
class PackageIndex:
    """Name -> manifest for every visible package; ``roots`` lists where it looked, in order."""

    roots: list[Path]
    packages: dict[str, PackageManifest] = field(default_factory=dict)
    #: packages found more than once under the same root (a workspace error catkin_make reports)
    duplicates: dict[str, list[Path]] = field(default_factory=dict)

    @classmethod
    def scan(cls, roots: list[Path]) -> PackageIndex:
        index = cls(roots=list(roots))
        for root in roots:
            local: dict[str, Path] = {}
            for pkg_dir in crawl(root):
                manifest = parse_manifest(pkg_dir / MANIFEST)
                if manifest.name in local:
                    index.duplicates.setdefault(manifest.name, [local[manifest.name]]).append(pkg_dir)
                    continue
                local[manifest.name] = pkg_dir
                index.packages.setdefault(manifest.name, manifest)
        return index

    @classmethod
    def from_environment(cls, env: Mapping[str, str] | None = None) -> PackageIndex:
        """Packages on ROS_PACKAGE_PATH, overlaying the ones ninjemys ships."""
        return cls.scan(package_path_dirs(env) + underlay_dirs())

    def find(self, name: str) -> PackageManifest:
        """The manifest of package ``name``; PackageError (rospack's wording) if it is nowhere."""
        try:
            return self.packages[name]
        except KeyError:
            raise PackageError(f"package '{name}' not found") from None

    def names(self) -> list[str]:
        return sorted(self.packages)

    def depends(self, name: str, recursive: bool = True) -> list[str]:
        """Run and build dependencies of ``name`` (known packages only), depth-first like rospack."""
        direct = [d for d in self.find(name).rospack_depends if d in self.packages]
        if not recursive:
            return direct
        order: list[str] = []
        visiting: set[str] = set()

        def visit(pkg: str) -> None:
            if pkg in visiting or pkg in order:
                return
            visiting.add(pkg)
            for dep in self.packages[pkg].rospack_depends:
                if dep in self.packages:
                    visit(dep)
            visiting.discard(pkg)
            order.append(pkg)

        for dep in direct:
            visit(dep)
        return order

    def depends_on(self, name: str, recursive: bool = True) -> list[str]:
        """Packages that depend on ``name`` (directly, or through others when ``recursive``)."""
        self.find(name)
        return sorted(
            other
            for other in self.packages
            if other != name and name in self.depends(other, recursive=recursive)
        )


def find_package(name: str, env: Mapping[str, str] | None = None) -> Path:
    """Directory of package ``name`` as ``rospack find`` and ``$(find name)`` report it."""
    return PackageIndex.from_environment(env).find(name).path
