"""Mesh files (STL binary and ASCII, COLLADA .dae, Wavefront .obj) reduced to their vertices, in parts.

No ROS in here. The simulator's world is a floor plan with heights, so a mesh obstacle only needs
where its triangles stand: each part's vertices, in metres, in the mesh's own frame (z up). A part is
one connected piece of an STL or OBJ (triangles sharing vertices) or one placed geometry of a
COLLADA scene, so a mesh of separate walls stays separate walls instead of one block. COLLADA's
``<unit meter>`` and ``<up_axis>`` are applied, and its scene's node transforms (``matrix``,
``translate``, ``rotate``, ``scale``) are composed down the node tree.

Every error is a :class:`MeshError` naming the file and why.
"""

from __future__ import annotations

import math
import struct
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ninjemys.maps.mapfile import MapFileError

#: vertices closer than this (metres) are the same vertex when finding an STL's connected parts
WELD = 1e-6
#: vertices farther than this from the mesh origin (metres) are a broken file, not a world
MAX_COORDINATE = 1e6
#: a mesh with more triangles than this is one part (finding components would cost more than it helps)
MAX_COMPONENT_TRIANGLES = 200_000


class MeshError(MapFileError):
    """A mesh file that cannot be read; the text names the file and the reason."""


@dataclass
class MeshPart:
    """One part of a mesh: its vertices (N, 3) and, where the file says how they join, its
    triangles (T, 3, 3); metres, z up."""

    vertices: np.ndarray
    triangles: np.ndarray


def load_mesh_parts(path: str | Path) -> list[np.ndarray]:
    """The mesh's parts, each an (N, 3) float array of vertex positions in metres (z up)."""
    return [part.vertices for part in load_mesh(path)]


def load_mesh(path: str | Path) -> list[MeshPart]:
    """The mesh's parts with their triangles (a maze of walls in one piece is cut at a height from
    them: its outline is not its convex hull)."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise MeshError(f"{p}: cannot read mesh: {exc.strerror or exc}") from None
    suffix = p.suffix.lower()
    if suffix == ".stl":
        parts = [_stl_triangles(data, p)]
    elif suffix == ".dae":
        collada = _collada_parts(data, p)
        parts = [c.vertices for c in collada] + [c.triangles for c in collada]
    elif suffix == ".obj":
        parts = [_obj_triangles(data, p)]
    else:
        raise MeshError(f"{p}: unsupported mesh format '{suffix}' (STL, DAE and OBJ are read)")
    for part in parts:
        if not np.isfinite(part).all():
            raise MeshError(f"{p}: a vertex is not a finite number (nan or inf)")
        if len(part) and np.abs(part).max() > MAX_COORDINATE:
            raise MeshError(f"{p}: a vertex lies more than {MAX_COORDINATE:g} m from the origin")
    if suffix == ".dae":
        return collada
    return [MeshPart(tris.reshape(-1, 3), tris) for tris in _components(parts[0])]


# -- STL -------------------------------------------------------------------------------------------


def _stl_triangles(data: bytes, p: Path) -> np.ndarray:
    """(T, 3, 3) triangle corners. Binary when the size matches the header's count, else ASCII."""
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if 84 + 50 * count == len(data):
            if not count:
                raise MeshError(f"{p}: binary STL with no triangles")
            rows = np.frombuffer(data, dtype=np.uint8, offset=84).reshape(count, 50)
            # each 50-byte record: normal (3 float32), three corners (9 float32), attribute (uint16)
            corners = rows[:, 12:48].copy().view("<f4").reshape(count, 3, 3)
            return corners.astype(np.float64)
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError:
        raise MeshError(
            f"{p}: neither a binary STL (size {len(data)} does not match its triangle count) "
            "nor an ASCII one (not text)"
        ) from None
    if not text.lstrip().lower().startswith("solid"):
        raise MeshError(f"{p}: not an STL file (binary size mismatch, and no 'solid' header)")
    verts: list[tuple[float, float, float]] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        words = line.split()
        if words and words[0].lower() == "vertex":
            try:
                x, y, z = (float(w) for w in words[1:4])
            except ValueError:
                raise MeshError(
                    f"{p}:{lineno}: vertex: expected three numbers, got {line.strip()!r}"
                ) from None
            verts.append((x, y, z))
    if not verts or len(verts) % 3:
        raise MeshError(f"{p}: ASCII STL with {len(verts)} vertices (expected a positive multiple of 3)")
    return np.array(verts, dtype=np.float64).reshape(-1, 3, 3)


# -- OBJ -------------------------------------------------------------------------------------------


def _obj_triangles(data: bytes, p: Path) -> np.ndarray:
    text = data.decode("utf-8", errors="replace")
    verts: list[tuple[float, float, float]] = []
    faces: list[list[int]] = []
    for lineno, line in enumerate(text.splitlines(), 1):
        words = line.split()
        if not words:
            continue
        try:
            if words[0] == "v":
                verts.append((float(words[1]), float(words[2]), float(words[3])))
            elif words[0] == "f":
                refs = [int(w.split("/")[0]) for w in words[1:]]
                faces.append([i - 1 if i > 0 else len(verts) + i for i in refs])
        except (ValueError, IndexError):
            raise MeshError(f"{p}:{lineno}: {words[0]}: cannot read {line.strip()!r}") from None
    if not verts or not faces:
        raise MeshError(f"{p}: OBJ with no vertices or no faces")
    v = np.array(verts)
    idx = np.array([(f[0], f[i], f[i + 1]) for f in faces for i in range(1, len(f) - 1)], dtype=np.int64)
    if not len(idx):
        raise MeshError(f"{p}: OBJ with no face of three or more vertices")
    if idx.min() < 0 or idx.max() >= len(v):
        raise MeshError(f"{p}: a face refers to a vertex that does not exist")
    return v[idx]


# -- connected parts -------------------------------------------------------------------------------


def _components(tris: np.ndarray) -> list[np.ndarray]:
    """Split (T, 3, 3) triangles into connected pieces (shared welded vertices), each (T', 3, 3)."""
    flat = tris.reshape(-1, 3)
    if len(tris) > MAX_COMPONENT_TRIANGLES or not len(tris):
        return [tris]
    keys = np.round(flat / WELD).astype(np.int64)
    _, vid = np.unique(keys, axis=0, return_inverse=True)
    vid = vid.reshape(-1)
    parent = np.arange(int(vid.max()) + 1)

    def find(i: int) -> int:
        root = i
        while parent[root] != root:
            root = parent[root]
        while parent[i] != root:
            parent[i], i = root, parent[i]
        return root

    for a, b, c in vid.reshape(-1, 3):
        ra, rb, rc = find(int(a)), find(int(b)), find(int(c))
        parent[rb] = ra
        parent[find(rc)] = ra
    roots = np.array([find(int(i)) for i in vid[::3]])
    return [tris[roots == root] for root in np.unique(roots)]


# -- COLLADA ---------------------------------------------------------------------------------------


def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


def _floats(text: str | None, p: Path, what: str) -> np.ndarray:
    try:
        return np.array([float(w) for w in (text or "").split()], dtype=np.float64)
    except ValueError:
        raise MeshError(f"{p}: {what}: expected numbers") from None


def _node_matrix(node: ET.Element, p: Path) -> np.ndarray:
    """The node's own transform: its transform children composed in document order."""
    m = np.eye(4)
    for child in node:
        tag = _local(child.tag)
        count = {"matrix": 16, "translate": 3, "scale": 3, "rotate": 4}.get(tag)
        if count is None:
            continue
        v = _floats(child.text, p, tag)
        if len(v) != count:
            raise MeshError(f"{p}: <{tag}> needs {count} numbers, got {len(v)}")
        if tag == "matrix":
            m = m @ v.reshape(4, 4)
        elif tag == "translate":
            t = np.eye(4)
            t[:3, 3] = v
            m = m @ t
        elif tag == "scale":
            m = m @ np.diag([v[0], v[1], v[2], 1.0])
        else:
            m = m @ _axis_angle(v[:3], math.radians(v[3]))
    return m


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    n = float(np.linalg.norm(axis))
    r = np.eye(4)
    if n == 0.0:
        return r
    x, y, z = axis / n
    c, s, t = math.cos(angle), math.sin(angle), 1 - math.cos(angle)
    r[:3, :3] = [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
    return r


def _geometry_positions(geom: ET.Element, p: Path) -> np.ndarray:
    """All vertex positions of a <geometry>'s <mesh> (the source its <vertices> POSITION names)."""
    mesh = next((c for c in geom if _local(c.tag) == "mesh"), None)
    if mesh is None:
        return np.zeros((0, 3))
    sources = {s.get("id"): s for s in mesh if _local(s.tag) == "source"}
    pos_id = None
    for vertices in (c for c in mesh if _local(c.tag) == "vertices"):
        for inp in vertices:
            if _local(inp.tag) == "input" and inp.get("semantic") == "POSITION":
                pos_id = (inp.get("source") or "").lstrip("#")
    src = sources.get(pos_id) if pos_id else None
    if src is None:
        raise MeshError(f"{p}: geometry '{geom.get('id')}' has no POSITION source")
    arr = next((c for c in src.iter() if _local(c.tag) == "float_array"), None)
    values = _floats(arr.text if arr is not None else "", p, f"source '{pos_id}'")
    if len(values) % 3:
        raise MeshError(f"{p}: source '{pos_id}': {len(values)} numbers is not a list of xyz points")
    return values.reshape(-1, 3)


def _geometry_triangles(geom: ET.Element, positions: np.ndarray, p: Path) -> np.ndarray:
    """The (T, 3, 3) triangles of a <geometry>'s <triangles>, <polylist> and <polygons> (polygons
    as fans), from the VERTEX input's indices into ``positions``."""
    mesh = next((c for c in geom if _local(c.tag) == "mesh"), None)
    out: list[np.ndarray] = []
    for prim in mesh if mesh is not None else []:
        kind = _local(prim.tag)
        if kind not in ("triangles", "polylist", "polygons"):
            continue
        inputs = [c for c in prim if _local(c.tag) == "input"]
        try:
            offsets = [int(i.get("offset", "0")) for i in inputs]
            vertex = next(int(i.get("offset", "0")) for i in inputs if i.get("semantic") == "VERTEX")
        except (ValueError, StopIteration):
            continue  # no vertex indices: the positions alone give the outline
        stride = max(offsets) + 1
        polys: list[np.ndarray] = []
        lists = [c for c in prim if _local(c.tag) == "p"]
        for plist in lists:
            idx = _floats(plist.text, p, f"<{kind}> <p>").astype(np.int64)[vertex::stride]
            if kind == "polygons":
                polys.append(idx)
            elif kind == "triangles":
                polys.extend(idx[: len(idx) // 3 * 3].reshape(-1, 3))
            else:
                vcount_el = next((c for c in prim if _local(c.tag) == "vcount"), None)
                counts = _floats(vcount_el.text if vcount_el is not None else "", p, "<vcount>").astype(
                    np.int64
                )
                starts = np.concatenate([[0], np.cumsum(counts)])
                if starts[-1] > len(idx):
                    raise MeshError(f"{p}: <polylist> <vcount> asks for more indices than <p> has")
                polys.extend(idx[a:b] for a, b in zip(starts[:-1], starts[1:], strict=True))
        for poly in polys:
            if len(poly) < 3:
                continue
            if poly.min() < 0 or poly.max() >= len(positions):
                raise MeshError(
                    f"{p}: <{kind}> index {int(poly.max())} is past the {len(positions)} positions"
                )
            fan = np.column_stack([np.full(len(poly) - 2, poly[0]), poly[1:-1], poly[2:]])
            out.append(positions[fan])
    return np.concatenate(out) if out else np.zeros((0, 3, 3))


def _collada_parts(data: bytes, p: Path) -> list[MeshPart]:
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line = exc.position[0] if exc.position else 0
        raise MeshError(f"{p}:{line}: not a COLLADA document: {exc}") from None
    if _local(root.tag) != "COLLADA":
        raise MeshError(f"{p}: root element is <{_local(root.tag)}>, not <COLLADA>")
    unit, up = 1.0, "Y_UP"
    for asset in (c for c in root if _local(c.tag) == "asset"):
        for c in asset:
            if _local(c.tag) == "unit":
                try:
                    unit = float(c.get("meter", "1") or 1)
                except ValueError:
                    raise MeshError(f"{p}: <unit meter={c.get('meter')!r}>: expected a number") from None
            elif _local(c.tag) == "up_axis":
                up = (c.text or "Y_UP").strip()
    geometries = {g.get("id"): g for g in root.iter() if _local(g.tag) == "geometry"}
    fix = np.eye(4)
    if up == "Y_UP":  # y up to z up: a quarter turn about x
        fix[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    elif up == "X_UP":
        fix[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    fix = np.diag([unit, unit, unit, 1.0]) @ fix
    parts: list[MeshPart] = []
    scenes = [s for s in root.iter() if _local(s.tag) == "visual_scene"]

    def placed(geom: ET.Element, m: np.ndarray) -> MeshPart | None:
        pts = _geometry_positions(geom, p)
        if not len(pts):
            return None
        tris = _geometry_triangles(geom, pts, p)
        h = np.hstack([pts, np.ones((len(pts), 1))]) @ m.T
        t = tris.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
        return MeshPart(h[:, :3], t.reshape(-1, 3, 3))

    def walk(node: ET.Element, m: np.ndarray) -> None:
        m = m @ _node_matrix(node, p)
        for child in node:
            tag = _local(child.tag)
            if tag == "instance_geometry":
                geom = geometries.get((child.get("url") or "").lstrip("#"))
                part = placed(geom, m) if geom is not None else None
                if part is not None:
                    parts.append(part)
            elif tag == "node":
                walk(child, m)

    for scene in scenes[:1]:
        for node in (c for c in scene if _local(c.tag) == "node"):
            walk(node, fix)
    if not scenes:
        for geom in geometries.values():
            part = placed(geom, fix)
            if part is not None:
                parts.append(part)
    if not parts:
        raise MeshError(f"{p}: COLLADA document with no geometry")
    return parts


def write_binary_stl(path: str | Path, triangles: np.ndarray, header: bytes = b"ninjemys") -> None:
    """Write (T, 3, 3) triangles as a binary STL (normals from the winding): for tests and shipped models."""
    tris = np.asarray(triangles, dtype=np.float32).reshape(-1, 3, 3)
    normals = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.where(lengths > 0, normals / np.where(lengths > 0, lengths, 1), 0).astype(np.float32)
    out = bytearray(header[:80].ljust(80, b" "))
    out += struct.pack("<I", len(tris))
    for n, t in zip(normals, tris, strict=True):
        out += struct.pack("<12fH", *n, *t.reshape(-1), 0)
    Path(path).write_bytes(bytes(out))
