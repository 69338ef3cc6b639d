"""``.rviz`` files: rviz 1's YAML layout, read into the page's display list and written back.

rviz keeps its configuration under ``Visualization Manager``: ``Displays`` (each with ``Class``,
``Name``, ``Enabled``, a topic key and display-specific keys; ``rviz/Group`` nests ``Displays``),
``Global Options`` (``Fixed Frame``, ``Background Color``), ``Tools`` (the topics of the pose/goal/
point tools) and ``Views``. We read what the page can show, name the displays it cannot (they are kept
and written back untouched), and keep every key we do not use, so a file saved by the page still opens
in real rviz with its panels, views and window geometry.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ninjemys.errors import NinjemysError

#: rviz display classes the page draws -> the key that holds their topic
SUPPORTED: dict[str, str | None] = {
    "rviz/Grid": None,
    "rviz/TF": None,
    "rviz/RobotModel": "Robot Description",
    "rviz/LaserScan": "Topic",
    "rviz/PointCloud2": "Topic",
    "rviz/Map": "Topic",
    "rviz/Path": "Topic",
    "rviz/Pose": "Topic",
    "rviz/PoseArray": "Topic",
    "rviz/PoseWithCovariance": "Topic",
    "rviz/Odometry": "Topic",
    "rviz/Marker": "Marker Topic",
    "rviz/MarkerArray": "Marker Topic",
    "rviz/Image": "Image Topic",
    "rviz/Polygon": "Topic",
}

#: the tools' default topics (rviz's own defaults)
DEFAULT_TOOLS = {
    "rviz/SetInitialPose": "/initialpose",
    "rviz/SetGoal": "/move_base_simple/goal",
    "rviz/PublishPoint": "/clicked_point",
}


class RvizConfigError(NinjemysError):
    """A .rviz file that cannot be read; the message starts with ``file:line:``."""


@dataclass
class RvizConfig:
    """A parsed .rviz file: what the page needs, plus the whole document to write back."""

    fixed_frame: str = "map"
    background: str = "48; 48; 48"
    frame_rate: float = 30.0
    displays: list[dict[str, Any]] = field(default_factory=list)
    unsupported: list[dict[str, Any]] = field(default_factory=list)
    tools: dict[str, str] = field(default_factory=lambda: dict(DEFAULT_TOOLS))
    #: the current view: {"mode": "top"|"orbit", "scale": px per m, "x", "y": focal point}
    view: dict[str, Any] = field(default_factory=dict)
    document: dict[str, Any] = field(default_factory=dict)

    def to_page(self) -> dict[str, Any]:
        """The JSON the page loads (``GET /api/rviz/config``)."""
        return {
            "fixedFrame": self.fixed_frame,
            "background": self.background,
            "frameRate": self.frame_rate,
            "displays": self.displays,
            "unsupported": self.unsupported,
            "tools": self.tools,
            "view": self.view,
        }


def _display(entry: dict[str, Any]) -> dict[str, Any]:
    cls = str(entry.get("Class", ""))
    key = SUPPORTED.get(cls)
    topic = entry.get(key) if key else None
    if cls == "rviz/Image" and topic is None:
        topic = entry.get("Topic")  # older files
    return {
        "cls": cls,
        "name": str(entry.get("Name", cls.split("/")[-1])),
        "enabled": bool(entry.get("Enabled", True)),
        "topic": str(topic) if topic is not None else "",
        "color": str(entry["Color"]) if "Color" in entry else None,
        "options": {
            k: v for k, v in entry.items() if k not in ("Class", "Name", "Enabled", "Color", key, "Displays")
        },
    }


def _flatten(displays: list[Any], where: str, into: RvizConfig) -> None:
    for i, entry in enumerate(displays):
        if not isinstance(entry, dict):
            raise RvizConfigError(f"{where}[{i}]: a display must be a mapping, got {type(entry).__name__}")
        cls = str(entry.get("Class", ""))
        if cls == "rviz/Group":
            _flatten(entry.get("Displays") or [], f"{where}[{i}].Displays", into)
        elif cls in SUPPORTED:
            into.displays.append(_display(entry))
        else:
            into.unsupported.append(
                {
                    "cls": cls or "(no Class)",
                    "name": str(entry.get("Name", "")),
                    "topic": entry.get("Topic", ""),
                }
            )


def parse(text: str, source: str = "<rviz config>") -> RvizConfig:
    """Parse a .rviz document; errors name ``source:line``."""
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f"{mark.line + 1}" if mark is not None else "?"
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise RvizConfigError(f"{source}:{line}: {problem}") from None
    if doc is None:
        doc = {}
    if not isinstance(doc, dict):
        raise RvizConfigError(f"{source}:1: a .rviz file is a YAML mapping, got {type(doc).__name__}")
    config = RvizConfig(document=doc)
    manager = doc.get("Visualization Manager") or {}
    if not isinstance(manager, dict):
        raise RvizConfigError(f"{source}: 'Visualization Manager' must be a mapping")
    displays = manager.get("Displays") or []
    if not isinstance(displays, list):
        raise RvizConfigError(f"{source}: 'Visualization Manager.Displays' must be a list")
    _flatten(displays, f"{source}: Displays", config)
    options = manager.get("Global Options") or {}
    if isinstance(options, dict):
        config.fixed_frame = str(options.get("Fixed Frame", config.fixed_frame))
        config.background = str(options.get("Background Color", config.background))
        if isinstance(options.get("Frame Rate"), int | float) and options["Frame Rate"] > 0:
            config.frame_rate = float(options["Frame Rate"])
    current = (manager.get("Views") or {}).get("Current") if isinstance(manager.get("Views"), dict) else None
    if isinstance(current, dict):
        top = current.get("Class") == "rviz/TopDownOrtho"
        config.view = {"mode": "top" if top else "orbit"}
        if top:
            for key, name in (("Scale", "scale"), ("X", "x"), ("Y", "y")):
                if isinstance(current.get(key), int | float):
                    config.view[name] = current[key]
        elif isinstance(current.get("Focal Point"), dict):
            config.view["x"] = current["Focal Point"].get("X", 0)
            config.view["y"] = current["Focal Point"].get("Y", 0)
    for tool in manager.get("Tools") or []:
        if isinstance(tool, dict) and tool.get("Class") in DEFAULT_TOOLS and tool.get("Topic"):
            config.tools[str(tool["Class"])] = str(tool["Topic"])
    return config


def load(path: str | Path) -> RvizConfig:
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise RvizConfigError(f"{p}: {exc.strerror or exc}") from None
    return parse(text, str(p))


def default_config() -> RvizConfig:
    """What rviz opens with no file: a grid in the map frame (and the TF display)."""
    config = RvizConfig()
    config.displays = [
        {
            "cls": "rviz/Grid",
            "name": "Grid",
            "enabled": True,
            "topic": "",
            "color": "160; 160; 164",
            "options": {},
        },
        {"cls": "rviz/TF", "name": "TF", "enabled": True, "topic": "", "color": None, "options": {}},
    ]
    return config


def _entry(display: dict[str, Any]) -> dict[str, Any]:
    cls = str(display["cls"])
    entry: dict[str, Any] = {"Class": cls}
    entry.update(display.get("options") or {})
    if display.get("color"):
        entry["Color"] = str(display["color"])
    entry["Enabled"] = bool(display.get("enabled", True))
    entry["Name"] = str(display.get("name") or cls.split("/")[-1])
    key = SUPPORTED.get(cls)
    if key:
        entry[key] = str(display.get("topic") or "")
    entry["Value"] = entry["Enabled"]
    return dict(sorted(entry.items()))  # rviz writes keys sorted


def dump(page: dict[str, Any], base: RvizConfig | None = None) -> str:
    """The YAML of the page's state (``POST /api/rviz/config``), over ``base``'s document so that
    panels, views, tools and the displays the page cannot show are kept."""
    doc = copy.deepcopy(base.document) if base is not None else {}
    manager = doc.setdefault("Visualization Manager", {})
    if not isinstance(manager, dict):
        manager = doc["Visualization Manager"] = {}
    manager.setdefault("Class", "")
    displays = [_entry(d) for d in page.get("displays", [])]
    if base is not None:  # what the page could not show goes back as it was
        kept = [e for e in _walk(manager.get("Displays") or []) if e.get("Class") not in SUPPORTED]
        displays.extend(kept)
    manager["Displays"] = displays
    manager["Enabled"] = True
    options = manager.setdefault("Global Options", {})
    options["Fixed Frame"] = str(page.get("fixedFrame") or "map")
    options.setdefault("Background Color", "48; 48; 48")
    options.setdefault("Default Light", True)
    options.setdefault("Frame Rate", 30)
    manager.setdefault("Name", "root")
    if "Tools" not in manager:
        manager["Tools"] = [
            {"Class": "rviz/Interact", "Hide Inactive Objects": True},
            {"Class": "rviz/MoveCamera"},
        ]
        manager["Tools"] += [{"Class": c, "Topic": t} for c, t in DEFAULT_TOOLS.items()]
    manager.setdefault("Value", True)
    return yaml.safe_dump(doc, default_flow_style=False, sort_keys=False, allow_unicode=True)


def _walk(displays: list[Any]) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for entry in displays:
        if isinstance(entry, dict):
            if entry.get("Class") == "rviz/Group":
                out.extend(_walk(entry.get("Displays") or []))
            else:
                out.append(entry)
    return out
