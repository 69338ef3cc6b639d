"""Mesh and texture files for the browser's rviz, by the URIs robot descriptions name them with.

A URDF names its meshes ``package://pkg/meshes/base.stl`` or ``file:///abs/path.dae``; the page asks
``GET /api/resource?uri=...`` and gets the file's bytes. Packages are found as ``rospack find`` finds
them (ROS_PACKAGE_PATH, then ninjemys' shipped packages). Only files inside a package directory are
served, whatever the URI says: ``..`` and symlinks out of the package, and ``file://`` paths outside
every package, are refused (403), so the page cannot be used to read the rest of the disk.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Mapping
from pathlib import Path
from urllib.parse import unquote

from ninjemys.errors import PackageError
from ninjemys.packages.discovery import PackageIndex
from ninjemys.serve.http import HttpError, Request, Response

ROUTE = "/api/resource"

#: what browsers' loaders expect; anything else in a package is served as bytes
CONTENT_TYPES = {
    ".stl": "model/stl",
    ".dae": "model/vnd.collada+xml",
    ".obj": "model/obj",
    ".mtl": "model/mtl",
    ".png": "image/png",
    ".jpg": "image/jpeg",
    ".jpeg": "image/jpeg",
    ".tga": "image/x-tga",
}


class Resources:
    """The resource route of one web app. The package index is crawled at most every ``ttl`` seconds
    (a robot's meshes arrive in a burst; a crawl of a large ROS_PACKAGE_PATH takes a while)."""

    def __init__(self, env: Mapping[str, str] | None = None, ttl: float = 10.0) -> None:
        self.env = env
        self.ttl = ttl
        self._index: PackageIndex | None = None
        self._at = 0.0
        self._lock = threading.Lock()

    def index(self) -> PackageIndex:
        with self._lock:
            now = time.monotonic()
            if self._index is None or now - self._at > self.ttl:
                self._index, self._at = PackageIndex.from_environment(self.env), now
            return self._index

    def resolve(self, uri: str) -> Path:
        """The file a ``package://`` or ``file://`` URI names, if inside a package (HttpError otherwise)."""
        index = self.index()
        if uri.startswith("package://"):
            name, _, rest = uri[len("package://") :].partition("/")
            try:
                root = index.find(name).path.resolve()
            except PackageError:
                raise HttpError(404, f"package '{name}' of {uri} not found on ROS_PACKAGE_PATH") from None
            path = (root / unquote(rest)).resolve()
            if not path.is_relative_to(root):
                raise HttpError(403, f"{uri} points outside package '{name}'")
        elif uri.startswith("file://"):
            path = Path(unquote(uri[len("file://") :])).resolve()
            roots = [p.path.resolve() for p in index.packages.values()]
            if not any(path.is_relative_to(r) for r in roots):
                raise HttpError(403, f"{uri} is not inside a ROS package: only package files are served")
        else:
            raise HttpError(400, f"expected a package:// or file:// URI, got {uri!r}")
        if not path.is_file():
            raise HttpError(404, f"{uri}: no such file ({path})")
        return path

    def handle(self, request: Request) -> Response:
        """``GET /api/resource?uri=package://...``: the file's bytes, with the type a loader expects."""
        uri = request.arg("uri")
        if not uri:
            raise HttpError(400, "GET /api/resource needs ?uri=package://PKG/PATH or file:///PATH")
        path = self.resolve(uri)
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise HttpError(500, f"cannot read {path}: {exc.strerror or exc}") from None
        content_type = CONTENT_TYPES.get(path.suffix.lower(), "application/octet-stream")
        return Response(data, 200, content_type, {"Cache-Control": "no-cache"})
