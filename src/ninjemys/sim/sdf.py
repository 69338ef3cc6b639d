"""Gazebo worlds (SDF 1.4-1.7 ``.world`` files) read into the simulator's floor-plan :class:`World`.

No ROS in here. A lidar in Gazebo hits collision geometry, so every ``<collision>`` of every model
becomes one obstacle: its footprint on the floor (the outline of the shape's projection), its bottom
and its top, coloured by its link's ``<visual>`` material. Heights are where Gazebo's physics leaves
the model: a ``<static>`` model stays at its pose (a table top held at 0.75 m: a low lidar and a low
robot pass under it), one with physics falls onto the floor (or is pushed up out of it) as a whole.
A model of several pieces gives one obstacle per piece, each knowing its model. Poses compose down the tree
(world, nested models, link, collision; x y z roll pitch yaw, fixed axes as SDF says), so a tilted
box or a lying cylinder gets the footprint it really has.

* Shapes: ``box``, ``cylinder``, ``sphere``, ``polyline`` (an extruded outline) and ``mesh`` (STL,
  COLLADA, OBJ, with ``<scale>``): a mesh becomes the convex hull of each connected part's projected
  vertices (:mod:`ninjemys.sim.meshes`), as tall as its highest vertex. ``plane`` is the floor.
* ``<include>`` of ``model://NAME`` is found as Gazebo finds it: ``GAZEBO_MODEL_PATH``, then
  ``~/.gazebo/models``, then the models that ship with us (``ground_plane``, ``sun`` and a few simple
  obstacles, share/gazebo_models). The include's ``<name>``, ``<pose>`` and ``<static>`` override
  the model's. Mesh URIs may be ``model://``, ``package://`` (ROS_PACKAGE_PATH), ``file://`` (a
  relative one, ``file://media/...``, on GAZEBO_RESOURCE_PATH, then beside the file) or a path
  relative to the file.
* A saved world's ``<state>`` moves its models to the poses saved there, as Gazebo does on load.
* Materials: ``<diffuse>``, else ``<ambient>``, else a script: ``Gazebo/Red``-style stock names
  (:mod:`ninjemys.sim.gazebo_materials`), else the colour the ``.material`` files its ``<uri>``s name
  give it; a material found nowhere is drawn grey and named once in the warning.
* What has no place in a floor plan (lights, physics, plugins, actors, joints ...) is skipped; the
  elements that would have changed what sensors see are reported once, in one warning.

Malformed SDF raises :class:`SdfError` with ``file:line: <element>: reason``.
"""

from __future__ import annotations

import functools
import logging
import math
import os
import re
import xml.etree.ElementTree as ET
import xml.parsers.expat
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ninjemys.errors import PackageError
from ninjemys.maps.mapfile import MapFileError
from ninjemys.packages.discovery import crawl, find_package
from ninjemys.sim.gazebo_materials import STOCK, TEXTURED, material_block, script_colour, stock_colour
from ninjemys.sim.lighting import GAZEBO_AMBIENT, GAZEBO_BACKGROUND, GAZEBO_SUN, Lighting, Sun
from ninjemys.sim.meshes import load_mesh
from ninjemys.sim.world2d import FloorImage, Obstacle, World

log = logging.getLogger(__name__)

#: the models that ship with ninjemys (ground_plane, sun, unit shapes ...), last on the model path
SHIPPED_MODELS = Path(__file__).resolve().parent.parent / "packages" / "share" / "gazebo_models" / "models"
SUPPORTED_VERSIONS = ("1.4", "1.5", "1.6", "1.7")
#: sides of the polygon that stands for a round outline (as world2d's cylinders)
ROUND_SIDES = 24
#: shapes whose top is lower than this (metres) lie on the floor: nothing for a sensor to hit
MIN_TOP = 1e-3
DEFAULT_COLOUR = (180, 180, 180)
MAX_INCLUDE_DEPTH = 16

#: Gazebo's stock material names as colours (kept in :mod:`ninjemys.sim.gazebo_materials`)
GAZEBO_MATERIALS = STOCK
#: where ``file://media/...`` of Gazebo's own resources is looked for when GAZEBO_RESOURCE_PATH is unset
DEFAULT_RESOURCE_PATH = "/usr/share/gazebo-11:/usr/share/gazebo"

#: elements that change nothing a sensor of the floor plan sees: skipped without a word
_QUIET_WORLD = {
    "light", "physics", "scene", "gui", "gravity", "magnetic_field", "atmosphere",
    "spherical_coordinates", "wind", "audio", "frame",
}  # fmt: skip
_QUIET_MODEL = {
    "static", "pose", "joint", "allow_auto_disable", "enable_wind", "self_collide", "frame", "gripper",
}  # fmt: skip
_QUIET_LINK = {
    "pose", "inertial", "gravity", "kinematic", "self_collide", "velocity_decay", "must_be_base_link",
    "enable_wind", "audio_sink", "audio_source", "battery", "light", "frame", "projector",
}  # fmt: skip
_QUIET_COLLISION = {"pose", "surface", "max_contacts", "laser_retro", "frame"}


class SdfError(MapFileError):
    """A world or model file that cannot be read: ``file:line: <element>: reason``."""


# -- a small XML tree with line numbers ---------------------------------------------------------


@dataclass
class Element:
    """One XML element: tag, attributes, children, text, and the line it starts on."""

    tag: str
    attrib: dict[str, str]
    line: int
    source: str
    children: list[Element] = field(default_factory=list)
    text: str = ""

    def find(self, tag: str) -> Element | None:
        return next((c for c in self.children if c.tag == tag), None)

    def findall(self, tag: str) -> list[Element]:
        return [c for c in self.children if c.tag == tag]

    def value(self, tag: str) -> str | None:
        child = self.find(tag)
        return None if child is None else child.text.strip()

    def error(self, reason: str) -> SdfError:
        return SdfError(f"{self.source}:{self.line}: <{self.tag}>: {reason}")


#: an XML declaration (``<?xml version="1.0"?>``)
_DECLARATION = re.compile(rb"<\?xml\s[^>]*\?>")


def _stray_declarations_blanked(data: bytes) -> bytes:
    """The text with every XML declaration that is not at its very start blanked (newlines kept,
    so line numbers stay). sdformat's TinyXML reads a world with ``<?xml ...?>`` pasted into the
    middle (worlds assembled from a saved world and a model file have them) or after a blank line;
    expat refuses both ("XML or text declaration not at start of entity")."""

    def blank(m: re.Match[bytes]) -> bytes:
        if m.start() == 0:
            return m.group(0)
        return re.sub(rb"[^\n]", b" ", m.group(0))

    return _DECLARATION.sub(blank, data)


def parse_xml(data: bytes, source: str) -> Element:
    """The document's root element, each element knowing its line (expat; errors name file and line).
    Declarations out of place are read past, as sdformat (TinyXML) does."""
    data = _stray_declarations_blanked(data)
    parser = xml.parsers.expat.ParserCreate()
    stack: list[Element] = []
    root: list[Element] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        el = Element(tag, dict(attrs), parser.CurrentLineNumber, source)
        if stack:
            stack[-1].children.append(el)
        else:
            root.append(el)
        stack.append(el)

    def end(_tag: str) -> None:
        stack.pop()

    def chars(text: str) -> None:
        if stack:
            stack[-1].text += text

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as exc:
        raise SdfError(
            f"{source}:{exc.lineno}: not well-formed XML: {xml.parsers.expat.ErrorString(exc.code)}"
        ) from None
    return root[0]


# -- numbers and poses ---------------------------------------------------------------------------


def _numbers(el: Element, count: int, what: str) -> list[float]:
    words = el.text.split()
    if len(words) != count:
        raise el.error(f"expected {count} numbers ({what}), got {el.text.strip()!r}")
    try:
        values = [float(w) for w in words]
    except ValueError:
        raise el.error(f"expected {count} numbers ({what}), got {el.text.strip()!r}") from None
    if not all(math.isfinite(v) for v in values):
        raise el.error(f"expected finite numbers, got {el.text.strip()!r}")
    return values


def _number(parent: Element, tag: str, default: float | None = None, positive: bool = False) -> float:
    el = parent.find(tag)
    if el is None:
        if default is None:
            raise parent.error(f"missing <{tag}>")
        return default
    (value,) = _numbers(el, 1, tag)
    if positive and value <= 0:
        raise el.error(f"expected a number > 0, got {el.text.strip()!r}")
    return value


def _bool(el: Element) -> bool:
    text = el.text.strip().lower()
    if text in ("1", "true"):
        return True
    if text in ("0", "false"):
        return False
    raise el.error(f"expected true or false, got {el.text.strip()!r}")


def pose_matrix(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    """4x4 transform of an SDF pose: translation, then rotation R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    m = np.eye(4)
    m[:3, :3] = [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ]
    m[:3, 3] = (x, y, z)
    return m


# -- footprints ----------------------------------------------------------------------------------


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of (N, 2) points (Andrew's monotone chain)."""
    pts = np.unique(np.round(np.asarray(points, dtype=np.float64), 9), axis=0)
    if len(pts) < 3:
        return pts

    def half(seq: np.ndarray) -> list[np.ndarray]:
        chain: list[np.ndarray] = []
        for p in seq:
            while len(chain) >= 2:
                (ax, ay), (bx, by) = chain[-2], chain[-1]
                if (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax) > 1e-12:
                    break
                chain.pop()
            chain.append(p)
        return chain

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _round_points(radius: float, z0: float, z1: float) -> np.ndarray:
    a = np.arange(ROUND_SIDES) * (2 * math.pi / ROUND_SIDES)
    ring = np.column_stack([radius * np.cos(a), radius * np.sin(a)])
    return np.vstack(
        [np.column_stack([ring, np.full(ROUND_SIDES, z0)]), np.column_stack([ring, np.full(ROUND_SIDES, z1)])]
    )


def _transform(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    return pts @ m[:3, :3].T + m[:3, 3]


@dataclass
class Footprint:
    """One solid piece: outline on the floor (counter-clockwise), top height, shape kind."""

    outline: np.ndarray
    top: float
    kind: str
    bottom: float = 0.0


# -- the reader ----------------------------------------------------------------------------------


@dataclass
class _Context:
    env: Mapping[str, str]
    unsupported: dict[str, str] = field(default_factory=dict)  # what -> first place
    #: a world file: what cannot be found (a model:// of Gazebo's online database, a mesh) is left
    #: out and reported, as Gazebo loads the world without it ("Unable to find uri[...]")
    lenient: bool = False
    #: textured planes lying on the floor (a course's track), for the camera
    floor_images: list[FloorImage] = field(default_factory=list)
    #: each top-level model's pose (x, y, yaw), as /gazebo/model_states reports it
    origins: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    #: each top-level model's pose height, before it settles
    heights: dict[str, float] = field(default_factory=dict)
    #: the world's ``<light>``s, its own and its includes' (``model://sun``), for the camera
    lights: list[Element] = field(default_factory=list)

    def missing(self, uri: str, el: Element, exc: SdfError | None = None) -> None:
        """SdfError, or in a world a note that ``uri`` is left out (Gazebo's behaviour)."""
        if not self.lenient:
            raise exc or el.error(f"{uri} not found")
        self.skip(
            f"{uri.strip()} (not found, left out as Gazebo does: 'Unable to find uri[{uri.strip()}]')", el
        )

    def skip(self, what: str, el: Element) -> None:
        self.unsupported.setdefault(what, f"{el.source}:{el.line}")


def model_dirs(env: Mapping[str, str] | None = None) -> list[Path]:
    """Where ``model://`` URIs are looked up, in Gazebo's order, ending with our shipped models:
    GAZEBO_MODEL_PATH, the ``gazebo_model_path`` the packages on ROS_PACKAGE_PATH export (what
    gazebo_ros' paths plugin adds), ``~/.gazebo/models``."""
    environ = os.environ if env is None else env
    dirs = [Path(d) for d in environ.get("GAZEBO_MODEL_PATH", "").split(":") if d]
    dirs += [Path(d) for d in _exported_model_paths(environ.get("ROS_PACKAGE_PATH", ""))]
    home = environ.get("HOME")
    if home:
        dirs.append(Path(home) / ".gazebo" / "models")
    dirs.append(SHIPPED_MODELS)
    return dirs


def resource_dirs(env: Mapping[str, str]) -> list[Path]:
    """Where a relative ``file://`` URI (``file://media/materials/scripts/x.material``) is looked up,
    as Gazebo does: GAZEBO_RESOURCE_PATH, the ``gazebo_media_path`` the packages on ROS_PACKAGE_PATH
    export (the maker's puzzlebot_gazebo: ``${prefix}/models``), then Gazebo's own install."""
    roots = [r for r in (env.get("GAZEBO_RESOURCE_PATH") or "").split(":") if r]
    roots += _exported_model_paths(env.get("ROS_PACKAGE_PATH", ""), "gazebo_media_path")
    roots += DEFAULT_RESOURCE_PATH.split(":")
    return [Path(r) for r in dict.fromkeys(roots)]


@functools.lru_cache(maxsize=16)
def _exported_model_paths(ros_package_path: str, attribute: str = "gazebo_model_path") -> tuple[str, ...]:
    """``<export><gazebo_ros gazebo_model_path="${prefix}/models"/></export>`` (or another
    ``attribute``: ``gazebo_media_path``) of every package on ``ros_package_path`` (the maker's
    puzzlebot_world has it), ``${prefix}`` being the package's folder: gazebo_ros' paths plugin adds
    these to Gazebo's model (resource) path (``rospack plugins``)."""
    found: list[str] = []
    for root in (Path(d) for d in ros_package_path.split(":") if d):
        for pkg_dir in crawl(root):
            try:
                tree = ET.parse(pkg_dir / "package.xml")
            except (OSError, ET.ParseError):
                continue
            for export in tree.getroot().findall("export"):
                for gz in export.findall("gazebo_ros"):
                    value = gz.get(attribute)
                    if value:
                        found.append(value.replace("${prefix}", str(pkg_dir)))
    return tuple(found)


def resolve_uri(uri: str, el: Element, env: Mapping[str, str]) -> Path:
    """A file or model directory for ``model://``, ``package://``, ``file://`` or a relative path."""
    text = uri.strip()
    if text.startswith("model://"):
        rest = text[len("model://") :]
        name, _, tail = rest.partition("/")
        looked = model_dirs(env)
        for d in looked:
            if (d / name).is_dir():
                return d / name / tail if tail else d / name
        raise el.error(
            f"model '{name}' of {text} not found (looked in GAZEBO_MODEL_PATH, ~/.gazebo/models and "
            f"ninjemys' models: {', '.join(str(d) for d in looked)})"
        )
    if text.startswith("package://"):
        pkg, _, tail = text[len("package://") :].partition("/")
        try:
            pdir = find_package(pkg, env)
        except PackageError:
            raise el.error(f"package '{pkg}' of {text} not found on ROS_PACKAGE_PATH") from None
        return pdir / tail
    if text.startswith("file://"):
        rest = text[len("file://") :]
        if rest.startswith("/"):
            return Path(rest)
        # relative (``file://media/materials/...``): Gazebo looks on its resource path, then beside the file
        for candidate in [*(r / rest for r in resource_dirs(env)), Path(el.source).parent / rest]:
            if candidate.exists():
                return candidate
        return Path(el.source).parent / rest
    if "://" in text:
        raise el.error(f"cannot fetch {text}: only model://, package://, file:// and paths are read")
    path = Path(text)
    return path if path.is_absolute() else Path(el.source).parent / path


def _model_file(model_dir: Path, el: Element) -> Path:
    """The SDF of a model directory: model.config's newest <sdf> we read, else model.sdf."""
    config = model_dir / "model.config"
    if config.is_file():
        root = parse_xml(config.read_bytes(), str(config))
        best: tuple[tuple[int, ...], str] | None = None
        for sdf in root.findall("sdf"):
            version = sdf.attrib.get("version", "1.4")
            try:
                key = tuple(int(p) for p in version.split("."))
            except ValueError:
                key = (0,)
            if version in SUPPORTED_VERSIONS and (best is None or key > best[0]):
                best = (key, sdf.text.strip())
        if best is None and root.find("sdf") is not None:
            best = ((0,), root.findall("sdf")[0].text.strip())
        if best is not None:
            return model_dir / best[1]
    if (model_dir / "model.sdf").is_file():
        return model_dir / "model.sdf"
    raise el.error(f"{model_dir} has neither model.config nor model.sdf")


def _read_sdf(path: Path, ctx: _Context, where: Element | None = None) -> Element:
    try:
        data = path.read_bytes()
    except OSError as exc:
        msg = f"cannot read {path}: {exc.strerror or exc}"
        raise (where.error(msg) if where is not None else SdfError(f"{path}: {msg}")) from None
    return _sdf_root(data, str(path), ctx)


def _sdf_root(data: bytes, source: str, ctx: _Context) -> Element:
    root = parse_xml(data, source)
    if root.tag != "sdf":
        raise root.error("the root element of an SDF file is <sdf>")
    version = root.attrib.get("version")
    if version is None:
        raise root.error("missing attribute 'version'")
    if version not in SUPPORTED_VERSIONS:
        ctx.skip(f"SDF version {version} (read as 1.7)", root)
    return root


def _colour(link: Element, ctx: _Context, pictures: tuple[Element, ...] = ()) -> tuple[int, int, int]:
    """The colour of a link's first visual material: diffuse, ambient, then the script's name
    (``pictures``: visuals drawn as floor pictures, not looked at)."""
    for visual in link.findall("visual"):
        if any(visual is p for p in pictures):
            continue
        mat = visual.find("material")
        if mat is None:
            continue
        script = mat.find("script")
        picture = (script.value("name") or "").strip() if script is not None else ""
        for tag in ("diffuse", "ambient"):
            el = mat.find(tag)
            if el is not None:
                words = el.text.split()
                if len(words) not in (3, 4):
                    raise el.error(f"expected r g b [a] in 0-1, got {el.text.strip()!r}")
                rgb = _numbers(el, len(words), "r g b a")[:3]
                if any(v < 0 or v > 1 for v in rgb):
                    raise el.error(f"colour components are 0-1, got {el.text.strip()!r}")
                base = stock_colour(picture) if picture.lower() in TEXTURED else None
                if base is not None:  # a stock picture (bricks, wood): the colour tints it
                    return (round(base[0] * rgb[0]), round(base[1] * rgb[1]), round(base[2] * rgb[2]))
                return (round(rgb[0] * 255), round(rgb[1] * 255), round(rgb[2] * 255))
        if script is not None:
            name = (script.value("name") or "").strip()
            colour = stock_colour(name)
            if colour is None:
                colour = next(
                    (c for f in _script_files(script, ctx) if (c := script_colour(f, name)) is not None), None
                )
            if colour is not None:
                return colour
            ctx.skip(
                f"material script {name!r} (not found in Gazebo's stock names nor its <uri>s: drawn grey)",
                script,
            )
    return DEFAULT_COLOUR


def _floor_picture(visual: Element, m: np.ndarray, ctx: _Context, name: str) -> FloorImage | None:
    """A visual that is a horizontal ``<plane>`` with a textured material script (the course's
    tracks: ``model://track/materials/scripts`` + ``.../textures``, material ``track``) as a picture on
    the floor, wherever its height (the floor plan has one floor); None for anything else."""
    geom = visual.find("geometry")
    plane = geom.find("plane") if geom is not None else None
    mat = visual.find("material")
    script = mat.find("script") if mat is not None else None
    if plane is None or script is None:
        return None
    material = (script.value("name") or "").strip()
    if not material or stock_colour(material) is not None:
        return None
    size_el = plane.find("size")
    if size_el is None:
        return None
    width, height = _numbers(size_el, 2, "x y")
    normal_el = plane.find("normal")
    vm = m @ _pose(visual, ctx)
    normal = vm[:3, :3] @ np.array(_numbers(normal_el, 3, "x y z") if normal_el is not None else [0, 0, 1.0])
    if width <= 0 or height <= 0 or abs(normal[2]) < 0.99 * float(np.linalg.norm(normal)):
        return None  # a wall-like plane: nothing the floor shows
    texture = _texture(script, material, ctx)
    if texture is None:
        ctx.skip(f"material script {material!r} (no texture found for it: drawn grey)", script)
        return None
    import cv2  # the course's PNG/JPEG textures; cv2 is a dependency already (cv_bridge)

    bgr = cv2.imread(str(texture), cv2.IMREAD_COLOR)
    if bgr is None:
        ctx.skip(f"texture {texture} (not an image cv2 reads: drawn grey)", script)
        return None
    rgb = np.ascontiguousarray(bgr[:, :, ::-1])
    yaw = math.atan2(float(vm[1, 0]), float(vm[0, 0]))
    return FloorImage(name, rgb, float(vm[0, 3]), float(vm[1, 3]), width, height, yaw)


def _script_files(script: Element, ctx: _Context) -> list[Path]:
    """The ``.material`` files a material ``<script>``'s ``<uri>``s name (files, or folders of them).

    ``file://media/...`` (Gazebo's own resources, a relative path) is looked for on
    GAZEBO_RESOURCE_PATH, then beside the file that names it; ``model://`` and ``package://`` as for
    meshes."""
    files: list[Path] = []
    for uri in script.findall("uri"):
        try:
            path = resolve_uri(uri.text, uri, ctx.env)
        except SdfError:
            continue
        if path.is_dir():
            files.extend(sorted(path.glob("*.material")))
        elif path.is_file():
            files.append(path)
    return files


def _texture(script: Element, material: str, ctx: _Context) -> Path | None:
    """The image of ``material``'s first ``texture`` in the material scripts its ``<uri>``s name
    (folders of ``.material`` files, or files), looked for beside the script, in ``../textures``
    and in the folders the ``<uri>``s name, as Gazebo's resource paths find it."""
    dirs = [d for uri in script.findall("uri") if (d := _uri_dir(uri, ctx)) is not None]
    for script_file in _script_files(script, ctx):
        try:
            text = script_file.read_text(errors="replace")
        except OSError:
            continue
        body = material_block(text, material)
        if body is None:
            continue
        found = re.search(r"\btexture\s+([^\s}]+)", body)
        if found is None:
            return None
        for d in (script_file.parent, script_file.parent.parent / "textures", *dirs):
            candidate = d / found.group(1)
            if candidate.is_file():
                return candidate
        return None
    return None


def _uri_dir(uri: Element, ctx: _Context) -> Path | None:
    try:
        path = resolve_uri(uri.text, uri, ctx.env)
    except SdfError:
        return None
    return path if path.is_dir() else None


def _pose(el: Element, ctx: _Context) -> np.ndarray:
    pose = el.find("pose")
    if pose is None or not pose.text.strip():
        return np.eye(4)
    frame = pose.attrib.get("relative_to") or pose.attrib.get("frame")
    if frame:
        ctx.skip(f"pose relative to '{frame}' (taken relative to the parent)", pose)
    return _pose_matrix(pose, ctx)


def _pose_matrix(pose: Element, ctx: _Context) -> np.ndarray:
    """A ``<pose>``'s transform. Three numbers (``<pose>0 0 0.0</pose>``, in the maker's PuzzleBot
    models) are a position with no rotation, as Gazebo 11 loads those models (noted once); any other
    count is an SdfError naming the file and line."""
    words = pose.text.split()
    if len(words) == 3:
        ctx.skip("<pose> of 3 numbers (read as x y z, no rotation)", pose)
        x, y, z = _numbers(pose, 3, "x y z")
        return pose_matrix(x, y, z, 0.0, 0.0, 0.0)
    return pose_matrix(*_numbers(pose, 6, "x y z roll pitch yaw"))


def _geometry(geom: Element, m: np.ndarray, ctx: _Context) -> list[Footprint]:
    shapes = [c for c in geom.children if c.tag != "empty"]
    if not shapes:
        return []
    shape = shapes[0]
    kind = shape.tag
    if kind == "box":
        size_el = shape.find("size")
        if size_el is None:
            raise shape.error("missing <size>")
        sx, sy, sz = _numbers(size_el, 3, "x y z")
        if min(sx, sy, sz) <= 0:
            raise size_el.error(f"sizes must be > 0, got {size_el.text.strip()!r}")
        corners = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)]) / 2.0
        return [_piece(_transform(m, corners), "box")]
    if kind == "cylinder":
        r = _number(shape, "radius", positive=True)
        length = _number(shape, "length", positive=True)
        return [_piece(_transform(m, _round_points(r, -length / 2, length / 2)), "cylinder")]
    if kind == "sphere":
        r = _number(shape, "radius", positive=True)
        centre = m[:3, 3]
        a = np.arange(ROUND_SIDES) * (2 * math.pi / ROUND_SIDES)
        outline = np.column_stack([centre[0] + r * np.cos(a), centre[1] + r * np.sin(a)])
        return [Footprint(outline, float(centre[2] + r), "sphere", float(centre[2] - r))]
    if kind == "polyline":
        height = _number(shape, "height", positive=True)
        pts = []
        for point in shape.findall("point"):
            pts.append(_numbers(point, 2, "x y"))
        if len(pts) < 3:
            raise shape.error("a polyline needs at least three <point>s")
        flat = np.array(pts)
        solid = np.vstack(
            [
                np.column_stack([flat, np.zeros(len(flat))]),
                np.column_stack([flat, np.full(len(flat), height)]),
            ]
        )
        return [_piece(_transform(m, solid), "polyline")]
    if kind == "mesh":
        uri = shape.value("uri")
        if not uri:
            raise shape.error("missing <uri>")
        if shape.find("submesh") is not None:
            ctx.skip("mesh <submesh> (the whole mesh is used)", shape)
        scale = np.ones(3)
        scale_el = shape.find("scale")
        if scale_el is not None:
            scale = np.array(_numbers(scale_el, 3, "x y z"))
        try:
            path = resolve_uri(uri, shape, ctx.env)
        except SdfError as exc:
            ctx.missing(uri, shape, exc)
            return []
        if not path.exists():
            ctx.missing(uri, shape, shape.error(f"{path}: cannot read mesh: No such file or directory"))
            return []
        try:
            parts = load_mesh(path)
        except MapFileError as exc:
            raise shape.error(str(exc)) from None
        out: list[Footprint] = []
        for part in parts:
            if len(part.vertices):
                tris = _transform(m, part.triangles.reshape(-1, 3) * scale).reshape(-1, 3, 3)
                out += _mesh_footprints(_transform(m, part.vertices * scale), tris)
        return out
    if kind == "plane":
        return []  # the floor
    ctx.skip(f"<{kind}> geometry", shape)
    return []


def _cross_section(tris: np.ndarray, z: float) -> np.ndarray:
    """The (K, 4) segments where the plane at height ``z`` cuts the (T, 3, 3) triangles."""
    d = tris[:, :, 2] - z
    d = np.where(d == 0.0, 1e-12, d)  # a vertex on the plane counts as just above it
    above = d > 0
    cut = above.any(axis=1) & ~above.all(axis=1)
    t, dd = tris[cut], d[cut]
    ends = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        crosses = (dd[:, a] > 0) != (dd[:, b] > 0)
        with np.errstate(divide="ignore", invalid="ignore"):  # edges that do not cross: dropped below
            f = dd[:, a] / (dd[:, a] - dd[:, b])
            point = t[:, a, :2] + (t[:, b, :2] - t[:, a, :2]) * f[:, None]
        ends.append(np.where(crosses[:, None], point, np.nan))
    pts = np.stack(ends, axis=1)  # (K, 3 edges, 2): two of the three edges cross
    first = np.where(np.isnan(pts[:, 0, 0])[:, None], pts[:, 1], pts[:, 0])
    second = np.where(np.isnan(pts[:, 2, 0])[:, None], pts[:, 1], pts[:, 2])
    segs = np.hstack([first, second])
    return segs[np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]) > 1e-9]


def _mesh_footprints(vertices: np.ndarray, tris: np.ndarray) -> list[Footprint]:
    """A mesh part's footprint: its convex hull, unless its walls cut at a low height lie inside the
    hull (a maze, an L-shaped wall, a room exported as one mesh): then the cut's segments, each a
    thin wall as tall as the part, as Gazebo's rays meet the triangles themselves."""
    hull = _piece(vertices, "mesh")
    if len(tris) < 4 or len(hull.outline) < 3:
        return [hull]
    low, high = hull.bottom, hull.top
    z = low + min(0.05, 0.25 * (high - low))  # near the floor: where a planar lidar looks
    segs = _cross_section(tris, z)
    if not len(segs):
        return [hull]
    outline = hull.outline
    edges = np.hstack([outline, np.roll(outline, -1, axis=0)])
    mids = (segs[:, :2] + segs[:, 2:]) / 2.0
    # how far each cut segment's middle lies inside the hull: near its edge, the hull is the outline
    span = float(min(np.ptp(outline[:, 0]), np.ptp(outline[:, 1])))
    depth = _distance_to_segments(mids, edges).min(axis=1)
    if float(depth.max()) <= max(0.02, 0.1 * span):
        return [hull]
    return [Footprint(seg.reshape(2, 2), high, "mesh", low) for seg in segs]


def _distance_to_segments(points: np.ndarray, segs: np.ndarray) -> np.ndarray:
    """(P, S) distances from points to segments."""
    a, b = segs[None, :, :2], segs[None, :, 2:]
    ab = b - a
    ap = points[:, None, :] - a
    length2 = np.maximum((ab * ab).sum(axis=2), 1e-18)
    t = np.clip((ap * ab).sum(axis=2) / length2, 0.0, 1.0)
    closest = a + ab * t[:, :, None]
    return np.hypot(*(points[:, None, :] - closest).transpose(2, 0, 1))


def _piece(points: np.ndarray, kind: str) -> Footprint:
    z = points[:, 2]
    return Footprint(convex_hull(points[:, :2]), float(z.max()), kind, float(z.min()))


@dataclass
class _Solid:
    path: list[str]  # model names from the top, then link, then collision
    footprint: Footprint
    colour: tuple[int, int, int]
    static: bool = False  # its model is static: it stays where it is put
    #: a visual of a link with no collision (an ArUco board): seen by cameras only; it neither falls
    #: nor holds anything up here (Gazebo's would fall through the floor unless static, as they are)
    visual: bool = False


#: a piece lands on a support whose top is below its middle (a box spawned a little into a table
#: top is pushed up onto it, as Gazebo's contacts push it; one spawned mostly below falls past)
#: and overlaps its outline by more than this (m): shapes that only touch side by side hold nothing
TOUCH = 1e-6


@dataclass
class Support:
    """Something a falling model may land on: an outline (in the frame the falling pieces' outlines
    are in) and its top (m above the floor)."""

    outline: np.ndarray
    top: float
    lo: tuple[float, float] = (0.0, 0.0)  # its bounding box (set from the outline)
    hi: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        mn, mx = self.outline.min(axis=0), self.outline.max(axis=0)
        self.lo, self.hi = (float(mn[0]), float(mn[1])), (float(mx[0]), float(mx[1]))


def overlaps(a: np.ndarray, b: np.ndarray, margin: float = TOUCH) -> bool:
    """Whether two convex outlines (or 2-point walls), (K, 2) each, overlap by more than ``margin``
    (the separating-axis test: no edge normal of either separates them)."""
    for poly in (a, b):
        edges = np.roll(poly, -1, axis=0) - poly if len(poly) > 2 else (poly[1:] - poly[:1])
        for ex, ey in edges:
            n = np.array([-ey, ex])
            norm = float(np.hypot(*n))
            if norm < 1e-12:
                continue
            pa, pb = a @ n / norm, b @ n / norm
            if pa.max() - margin <= pb.min() or pb.max() - margin <= pa.min():
                return False
    return True


def rest_height(outline: np.ndarray, bottom: float, top: float, ground: list[Support]) -> float:
    """Where a falling piece (outline, bottom and top in metres) comes to rest: the highest top
    below its middle among the supports it overlaps, else the floor (0)."""
    middle = (bottom + top) / 2.0
    if len(outline) < 2:
        return 0.0
    (x0, y0), (x1, y1) = outline.min(axis=0), outline.max(axis=0)
    return max(
        (
            g.top
            for g in ground
            if 0.0 < g.top <= middle
            and g.lo[0] < x1
            and g.hi[0] > x0
            and g.lo[1] < y1
            and g.hi[1] > y0  # boxes first: cheap
            and overlaps(outline, g.outline)
        ),
        default=0.0,
    )


def _settle(
    solids: list[_Solid], drops: dict[str, float] | None = None, supports: list[Support] | None = None
) -> list[_Solid]:
    """Heights as Gazebo's physics leaves each top-level model (all its pieces together): a static
    model stays at its pose (a table top held at 0.75 m floats there; a part below the floor is
    hidden); a model with physics falls, or is pushed up, until one of its pieces rests on the floor
    or on what is under it: a static piece, a model that settled before it (lowest first: a stack of
    boxes) or one of ``supports`` (the world a spawned model falls into). Pieces with nothing above
    the floor are dropped. ``drops`` receives how far each model fell (negative: pushed up)."""
    ground: list[Support] = list(supports or [])
    for s in solids:
        if s.static and not s.visual and s.footprint.top > MIN_TOP:
            ground.append(Support(s.footprint.outline, s.footprint.top))
    models: dict[str, list[_Solid]] = {}
    for s in solids:
        if not s.static and not s.visual:
            models.setdefault(s.path[0], []).append(s)
    fallen: dict[str, float] = {}
    for name, pieces in sorted(models.items(), key=lambda kv: min(p.footprint.bottom for p in kv[1])):
        drop = math.inf
        for p in pieces:
            fp = p.footprint
            drop = min(drop, fp.bottom - rest_height(fp.outline, fp.bottom, fp.top, ground))
        fallen[name] = drop
        for p in pieces:
            ground.append(Support(p.footprint.outline, p.footprint.top - drop))
    if drops is not None:
        drops.update(fallen)
    kept = []
    for s in solids:
        fp = s.footprint
        drop = fallen.get(s.path[0], 0.0) if not (s.static or s.visual) else 0.0
        fp.top, fp.bottom = fp.top - drop, max(fp.bottom - drop, 0.0)
        if fp.top > MIN_TOP and len(fp.outline) >= 2:
            kept.append(s)
    return kept


def _model(
    el: Element,
    parent: np.ndarray,
    ctx: _Context,
    out: list[_Solid],
    scope: list[str],
    depth: int,
    pose_override: np.ndarray | None = None,
    static: bool | None = None,
) -> None:
    """Read a model's pieces into ``out``; ``static`` (an include's or a parent's) overrides its own."""
    name = el.attrib.get("name")
    if not name:
        raise el.error("missing attribute 'name'")
    m = parent @ (pose_override if pose_override is not None else _pose(el, ctx))
    here = [*scope, name]
    if not scope:
        ctx.origins[name] = (float(m[0, 3]), float(m[1, 3]), math.atan2(float(m[1, 0]), float(m[0, 0])))
        ctx.heights[name] = float(m[2, 3])
    if static is None:
        own = el.find("static")
        static = _bool(own) if own is not None else False
    for child in el.children:
        tag = child.tag
        if tag == "link":
            _link(child, m, ctx, out, here, static)
        elif tag == "model":
            _model(child, m, ctx, out, here, depth + 1, static=static or None)
        elif tag == "include":
            _include(child, m, ctx, out, here, depth + 1, static=static or None)
        elif tag == "plugin":
            ctx.skip(f"model plugin {child.attrib.get('filename', '?')}", child)
        elif tag not in _QUIET_MODEL:
            ctx.skip(f"<{tag}> in a model", child)


def _link(
    el: Element, model: np.ndarray, ctx: _Context, out: list[_Solid], scope: list[str], static: bool
) -> None:
    name = el.attrib.get("name")
    if not name:
        raise el.error("missing attribute 'name'")
    m = model @ _pose(el, ctx)
    pictures = []
    for visual in el.findall("visual"):
        picture = _floor_picture(visual, m, ctx, "::".join([*scope, name, visual.attrib.get("name", "")]))
        if picture is not None:
            ctx.floor_images.append(picture)
            pictures.append(visual)
    colour = _colour(el, ctx, tuple(pictures))
    for child in el.children:
        if child.tag == "collision":
            cname = child.attrib.get("name")
            if not cname:
                raise child.error("missing attribute 'name'")
            geom = child.find("geometry")
            if geom is None:
                raise child.error("missing <geometry>")
            for fp in _geometry(geom, m @ _pose(child, ctx), ctx):
                out.append(_Solid([*scope, name, cname], fp, colour, static))
            for sub in child.children:
                if sub.tag not in _QUIET_COLLISION and sub.tag != "geometry":
                    ctx.skip(f"<{sub.tag}> in a collision", sub)
        elif child.tag == "sensor":
            ctx.skip(f"<sensor type='{child.attrib.get('type', '?')}'> in a world model", child)
        elif child.tag != "visual" and child.tag not in _QUIET_LINK:
            ctx.skip(f"<{child.tag}> in a link", child)
    if el.find("collision") is None:
        # nothing to collide with: its visuals are for cameras only (a fiducial marker, a tag board)
        for visual in el.findall("visual"):
            geom = visual.find("geometry")
            if geom is None or any(visual is p for p in pictures):
                continue
            vname = visual.attrib.get("name", "visual")
            for fp in _geometry(geom, m @ _pose(visual, ctx), ctx):
                out.append(_Solid([*scope, name, vname], fp, colour, static, visual=True))


def _include(
    el: Element,
    parent: np.ndarray,
    ctx: _Context,
    out: list[_Solid],
    scope: list[str],
    depth: int,
    saved: dict[str, np.ndarray] | None = None,
    static: bool | None = None,
) -> None:
    if depth > MAX_INCLUDE_DEPTH:
        raise el.error(f"includes nested more than {MAX_INCLUDE_DEPTH} deep (a model including itself?)")
    uri = el.value("uri")
    if not uri:
        raise el.error("missing <uri>")
    try:
        target = resolve_uri(uri, el, ctx.env)
    except SdfError as exc:
        ctx.missing(uri, el, exc)
        return
    if not target.exists():
        ctx.missing(uri, el, el.error(f"{uri}: {target} does not exist"))
        return
    path = _model_file(target, el) if target.is_dir() else target
    root = _read_sdf(path, ctx, el)
    model = root.find("model")
    if model is None:
        if root.find("light") is not None:
            ctx.lights += root.findall("light")  # a light (Gazebo's sun is one): nothing solid
            return
        raise root.error(f"{uri}: no <model> in {path}")
    name = el.value("name")
    if name:
        model.attrib["name"] = name
    static_el = el.find("static")
    if static is None and static_el is not None:
        static = _bool(static_el)
    pose = el.find("pose")
    override = _pose_matrix(pose, ctx) if pose is not None else None
    if saved and model.attrib.get("name") in saved:
        override = saved[model.attrib["name"]]
    _model(model, parent, ctx, out, scope, depth, override, static)


def _state_poses(world: Element, ctx: _Context) -> dict[str, np.ndarray]:
    """Model poses saved in the world's ``<state>`` (a world saved from Gazebo's GUI)."""
    poses: dict[str, np.ndarray] = {}
    for state in world.findall("state"):
        for model in state.findall("model"):
            pose = model.find("pose")
            name = model.attrib.get("name")
            if name and pose is not None and pose.text.strip():
                poses[name] = _pose_matrix(pose, ctx)
    return poses


def load_sdf_world(
    path: str | Path,
    env: Mapping[str, str] | None = None,
    warn: Callable[[str], None] | None = None,
) -> World:
    """The simulator's World for a Gazebo ``.world`` file (SdfError naming file, line, element, reason)."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise SdfError(f"{p}: cannot read world: {exc.strerror or exc}") from None
    return parse_sdf_world(data, str(p), env, warn)


def parse_sdf_world(
    data: bytes | str,
    source: str,
    env: Mapping[str, str] | None = None,
    warn: Callable[[str], None] | None = None,
) -> World:
    """A World from SDF text (``source`` names it in errors; relative mesh paths start at its folder)."""
    ctx = _Context(os.environ if env is None else env, lenient=True)
    root = _sdf_root(data.encode() if isinstance(data, str) else data, source, ctx)
    world_el = root.find("world")
    if world_el is None:
        raise root.error("no <world> in this file (a model file? spawn it with spawn_model -sdf)")
    drops: dict[str, float] = {}
    solids = _settle(_world_solids(world_el, ctx), drops)
    world = World(world_el.attrib.get("name", Path(source).stem), _obstacles(solids), source=source)
    kept = {s.path[0] for s in solids}
    # every top-level model, in the file's order (Gazebo lists them so), the bare ones too (a ground plane)
    world.model_poses = dict(ctx.origins)
    world.model_heights = {name: z - drops.get(name, 0.0) for name, z in ctx.heights.items()}
    world.bare_models = [name for name in ctx.origins if name not in kept]
    world.dynamic_models = list(drops)  # models with physics: a set_model_state re-drops them
    world.placed_heights = {name: ctx.heights[name] for name in drops if name in ctx.heights}
    world.floor_images = ctx.floor_images
    world.lighting = _lighting(world_el, ctx)
    _report(ctx, source, warn)
    return world


def _colour_of(el: Element | None, default: tuple[float, float, float]) -> tuple[float, float, float]:
    """An SDF colour element's red, green and blue (alpha optional), each 0-1 (SdfError otherwise)."""
    if el is None:
        return default
    words = el.text.split()
    values = _numbers(el, len(words) if len(words) in (3, 4) else 4, "r g b a")
    if not all(0.0 <= v <= 1.0 for v in values):
        raise el.error(f"colour components are 0-1, got {el.text.strip()!r}")
    return (values[0], values[1], values[2])


def _lighting(world_el: Element, ctx: _Context) -> Lighting:
    """The camera's lights for a world: its ``<scene>``'s ambient and background (Gazebo's 0.4 and
    0.7 grey by default), its directional ``<light>``s (Gazebo's sun comes from ``model://sun``),
    the floor Gazebo's grey ground plane. A world with no directional light is lit by Gazebo's
    default sun (Gazebo would light it by the ambient alone, a dim grey picture: such a world is a
    fragment written without the usual ``model://sun``, not a night scene). Point and spot lights
    are not drawn (see :mod:`ninjemys.sim.lighting`)."""
    scene = world_el.find("scene")
    ambient = _colour_of(scene.find("ambient") if scene is not None else None, GAZEBO_AMBIENT)
    grey = GAZEBO_BACKGROUND[0] / 255.0
    background = _colour_of(scene.find("background") if scene is not None else None, (grey, grey, grey))
    suns = []
    for light in ctx.lights:
        if light.attrib.get("type", "point") != "directional":
            continue
        direction_el = light.find("direction")
        direction = (0.0, 0.0, -1.0) if direction_el is None else tuple(_numbers(direction_el, 3, "x y z"))
        if not any(direction):
            raise (direction_el or light).error("a directional light's <direction> must not be 0 0 0")
        suns.append(Sun(_colour_of(light.find("diffuse"), (1.0, 1.0, 1.0)), direction))  # type: ignore[arg-type]
    return Lighting(
        ambient,
        tuple(suns) if suns else (GAZEBO_SUN,),
        sky=(round(background[0] * 255), round(background[1] * 255), round(background[2] * 255)),
        floor=stock_colour("Gazebo/Grey"),
    )


def sdf_model_obstacles(
    data: bytes | str,
    source: str = "<spawn_sdf_model>",
    env: Mapping[str, str] | None = None,
    warn: Callable[[str], None] | None = None,
    z: float = 0.0,
    drops: dict[str, float] | None = None,
    supports: list[Support] | None = None,
    models: list[str] | None = None,
) -> list[Obstacle]:
    """The obstacles of an SDF model document (``<sdf><model>``, as spawn_sdf_model receives it, or a
    ``<world>`` of includes), their outlines in the model's frame (place them at the spawn pose),
    their heights as the model settles when spawned at height ``z``: a static model stays there, one
    with physics falls onto the floor or is pushed up out of it (:func:`_settle`). A model of several
    pieces (a table: top and legs) gives one obstacle per piece, each naming the model. ``drops``
    receives how far each model with physics fell from ``z`` (its pose after it settles: ``z - drop``);
    ``supports`` (outlines in the model's frame) are what it may land on besides the floor: the world
    it is spawned into (a box dropped over a table lands on the table); ``models`` receives the names
    of the models the document holds, in order (a ground plane is one, with no obstacle)."""
    ctx = _Context(os.environ if env is None else env)
    root = _sdf_root(data.encode() if isinstance(data, str) else data, source, ctx)
    solids: list[_Solid] = []
    world_el = root.find("world")
    if world_el is not None:
        solids = _world_solids(world_el, ctx)
    for model in root.findall("model"):
        _model(model, np.eye(4), ctx, solids, [], 0)
    if world_el is None and root.find("model") is None:
        raise root.error("no <model> in this SDF document")
    _report(ctx, source, warn)
    if models is not None:
        models.extend(ctx.origins)  # the models it holds (none for a light: Gazebo's sun)
    for solid in solids:
        solid.footprint.top += z
        solid.footprint.bottom += z
    return _obstacles(_settle(solids, drops, supports))


def _world_solids(world_el: Element, ctx: _Context) -> list[_Solid]:
    saved = _state_poses(world_el, ctx)
    solids: list[_Solid] = []
    for child in world_el.children:
        if child.tag == "model":
            name = child.attrib.get("name", "")
            _model(child, np.eye(4), ctx, solids, [], 0, saved.get(name))
        elif child.tag == "include":
            _include(child, np.eye(4), ctx, solids, [], 1, saved)
        elif child.tag == "plugin":
            ctx.skip(f"world plugin {child.attrib.get('filename', '?')}", child)
        elif child.tag == "light":
            ctx.lights.append(child)
        elif child.tag != "state" and child.tag not in _QUIET_WORLD:
            ctx.skip(f"<{child.tag}>", child)
    return solids


def _report(ctx: _Context, source: str, warn: Callable[[str], None] | None) -> None:
    if ctx.unsupported:
        listed = "; ".join(f"{what} ({where})" for what, where in ctx.unsupported.items())
        (warn or log.warning)(f"{source}: not simulated, ignored: {listed}")


def _obstacles(solids: list[_Solid]) -> list[Obstacle]:
    """One obstacle per collision piece, named by its top-level model when that model has one piece,
    else ``model::link::collision`` (``#n`` for the parts of one mesh), as Gazebo scopes names; the
    pieces of a model of several know their model (Gazebo's services move and delete it whole)."""
    per_model: dict[str, int] = {}
    for s in solids:
        per_model[s.path[0]] = per_model.get(s.path[0], 0) + 1
    seen: dict[str, int] = {}
    obstacles = []
    for s in solids:
        single = per_model[s.path[0]] == 1
        name = s.path[0] if single else "::".join(s.path)
        n = seen.get(name, 0)
        seen[name] = n + 1
        if n:
            name = f"{name}#{n}"
        fp = s.footprint
        obstacles.append(
            Obstacle(
                name,
                fp.kind,
                fp.outline,
                fp.top,
                s.colour,
                fp.bottom,
                "" if single else s.path[0],
                solid=not s.visual,
            )
        )
    return obstacles
