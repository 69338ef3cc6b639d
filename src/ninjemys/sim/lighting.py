"""How the simulator's camera lights a surface: Gazebo's rule for directional lights (its sun).

No ROS in here. Gazebo classic (OGRE) colours a surface lit by directional lights as

    material ambient * scene ambient + sum over lights of material diffuse * light diffuse * max(0, n . -d)

per channel, clamped to [0, 1], where ``n`` is the surface's normal and ``d`` the direction the light
travels: a directional light has no attenuation, so a surface's colour does not depend on its
distance. Gazebo's defaults, used by every world that does not say otherwise: the scene ambient 0.4
(SDF ``<scene><ambient>``), and the sun of its ``worlds/empty.world`` (``model://sun``): diffuse 0.8,
direction (-0.5, 0.1, -0.9). So a white ball's or box's top saturates at 255 at any distance, and a
white wall facing the sun is about 203 (0.4 + 0.8 x 0.493).

What is left out, and why: the specular term (materials' specular is 0.1 or less and lights' 0.2: a
few grey levels on a highlight), shadows, and point and spot lights (they attenuate with distance,
and the course worlds light with the sun alone). A material's ambient and diffuse colours are taken as
one colour (the obstacle's): Gazebo's stock materials mostly have them equal (``Gazebo/White`` is
1 1 1 in both). Our own YAML worlds are lit by the same rule and defaults.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

#: Gazebo's scene ambient when a world gives no ``<scene><ambient>``
GAZEBO_AMBIENT = (0.4, 0.4, 0.4)
#: Gazebo's background (the sky's colour in its camera images) when a world gives no ``<background>``
GAZEBO_BACKGROUND = (179, 179, 179)


@dataclass(frozen=True)
class Sun:
    """A directional light: its diffuse colour (0-1 per channel) and the direction its light travels."""

    diffuse: tuple[float, float, float]
    direction: tuple[float, float, float]

    def toward(self) -> tuple[float, float, float]:
        """The unit vector from a surface toward the light (``-direction``, normalised)."""
        dx, dy, dz = self.direction
        norm = math.sqrt(dx * dx + dy * dy + dz * dz)
        return (-dx / norm, -dy / norm, -dz / norm)


#: the sun of Gazebo's ``worlds/empty.world`` and of its ``model://sun``
GAZEBO_SUN = Sun((0.8, 0.8, 0.8), (-0.5, 0.1, -0.9))


@dataclass(frozen=True)
class Lighting:
    """A world's lights: the scene ambient (0-1 per channel), its directional lights, and the colours
    of the sky and of the bare floor (0-255, the floor's before lighting; None: the camera's own)."""

    ambient: tuple[float, float, float] = GAZEBO_AMBIENT
    suns: tuple[Sun, ...] = (GAZEBO_SUN,)
    sky: tuple[int, int, int] | None = None
    floor: tuple[int, int, int] | None = None

    @functools.cached_property
    def _terms(self) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:
        """(grey: every light and the ambient the same in all channels, ambient (3,), each sun's
        unit vector toward it (S, 3), each sun's diffuse (S, 3)), worked out once."""
        ambient = np.asarray(self.ambient, dtype=np.float64)
        toward = np.array([sun.toward() for sun in self.suns], dtype=np.float64).reshape(-1, 3)
        diffuse = np.array([sun.diffuse for sun in self.suns], dtype=np.float64).reshape(-1, 3)
        grey = bool((ambient == ambient[0]).all() and (diffuse == diffuse[:, :1]).all())
        return grey, ambient, toward, diffuse

    def factors(self, normals: np.ndarray) -> np.ndarray:
        """(N, 3): what each surface's colour is multiplied by, per channel, for unit ``normals``
        (N, 3)."""
        _grey, ambient, toward, diffuse = self._terms
        lambert = normals @ toward.T  # (N, S)
        np.maximum(lambert, 0.0, out=lambert)
        return lambert @ diffuse + ambient

    def shade(self, colours: np.ndarray, normals: np.ndarray) -> np.ndarray:
        """uint8 (N, 3): ``colours`` (N, 3, 0-255) lit on surfaces of unit ``normals`` (N, 3)."""
        grey, ambient, toward, diffuse = self._terms
        if grey:  # one factor per surface (the common case: white lights)
            factor = normals @ (toward.T if len(toward) > 1 else toward[0])
            np.maximum(factor, 0.0, out=factor)
            if len(toward) > 1:
                factor = factor @ diffuse[:, 0]
            else:
                factor *= diffuse[0, 0]
            factor += ambient[0]
            lit = colours * factor[:, None]
        else:
            lit = colours * self.factors(normals)
        np.rint(lit, out=lit)
        np.minimum(lit, 255.0, out=lit)
        return lit.astype(np.uint8)

    def shade_flat(self, colours: np.ndarray, normal: tuple[float, float, float]) -> np.ndarray:
        """uint8, ``colours``' shape (..., 3): every colour lit on one surface facing ``normal``."""
        f = self.factors(np.array([normal], dtype=np.float64))[0]
        lit = np.asarray(colours, dtype=np.float64) * f
        np.rint(lit, out=lit)
        np.clip(lit, 0.0, 255.0, out=lit)
        return lit.astype(np.uint8)


#: Gazebo's defaults: ambient 0.4 and the sun of ``worlds/empty.world``
DEFAULT_LIGHTING = Lighting()


@dataclass(frozen=True)
class SceneLook:
    """What the camera needs to light a world's obstacles, beside the scene's segments: the lights,
    and per obstacle (the scene's ``owners`` index these) the centre of a round one (a cylinder's or
    a sphere's axis: smooth normals, as Gazebo draws them, not the 24-gon's facets; NaN for a flat
    one) and a sphere's centre height and radius (NaN radius: not a sphere)."""

    lighting: Lighting = DEFAULT_LIGHTING
    round_centres: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    sphere_z: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sphere_r: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @functools.cached_property
    def any_round(self) -> bool:
        return bool(len(self.round_centres)) and not bool(np.isnan(self.round_centres[:, 0]).all())

    @functools.cached_property
    def any_sphere(self) -> bool:
        return bool(len(self.sphere_r)) and not bool(np.isnan(self.sphere_r).all())


def round_centre(outline: np.ndarray) -> tuple[float, float] | None:
    """The centre of an outline that is a regular polygon of many sides (a cylinder's or a sphere's
    footprint, a 24-gon), None for anything else (a box, a lying cylinder's hull)."""
    if len(outline) < 12:
        return None
    centre = outline.mean(axis=0)
    radii = np.hypot(outline[:, 0] - centre[0], outline[:, 1] - centre[1])
    if radii.max() <= 0.0 or radii.min() < 0.98 * radii.max():
        return None
    return float(centre[0]), float(centre[1])


class Shape(Protocol):
    """What :func:`scene_look` reads of an obstacle (``world2d.Obstacle``)."""

    kind: str
    outline: np.ndarray
    height: float
    base: float


def scene_look(lighting: Lighting, obstacles: Sequence[Shape]) -> SceneLook:
    """The :class:`SceneLook` of a world's obstacles, in their order."""
    n = len(obstacles)
    centres = np.full((n, 2), np.nan)
    sphere_z = np.full(n, np.nan)
    sphere_r = np.full(n, np.nan)
    for i, ob in enumerate(obstacles):
        if ob.kind not in ("cylinder", "sphere"):
            continue
        c = round_centre(ob.outline)
        if c is None:
            continue
        centres[i] = c
        if ob.kind == "sphere" and ob.height > ob.base:
            sphere_z[i] = (ob.height + ob.base) / 2.0
            sphere_r[i] = (ob.height - ob.base) / 2.0
    return SceneLook(lighting, centres, sphere_z, sphere_r)
