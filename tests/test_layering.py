"""Each layer imports only from the layers below it (docs/ARCHITECTURE's order), checked with ``ast``.

Every ``import`` and ``from ... import`` in src/ counts, wherever it sits (module top, inside a
function, under ``if TYPE_CHECKING``): a lazy import is still a dependency. A module may import its
own layer and any layer below; anything else fails with ``file:line``.

The order, bottom to top (``LAYERS``)::

    base       leaf modules every layer may use (errors, names, rostime, roshome, records, paramyaml, interrupt, ...)
    idl        message definitions and classes, and the interface stub packages (src/std_msgs, ...)
    packages   ROS packages on disk: discovery, manifests, shipped executables, catkin workspaces
    wire       ROS 1 serialization, TCPROS framing and headers, XML-RPC encoding (sans-IO)
    net        the node's event loop and the XML-RPC server/client on it
    master     registrations, parameter server, rosout log format
    node       the client runtime (Node and its parts)
    libs       cores built on Node: actionlib, tf2, message_filters, dynamic_reconfigure,
               laser_geometry, cv_bridge; and the launch and bag cores (plan/run, bag files,
               record/play), which the roslaunch and rosbag commands drive
    compat     the ROS 1 Python facades: every top-level package of src/ other than ninjemys
    tools      the commands (roscore, rostopic, ..., rosout), ninjemys.testing
    apps       sim, nav, bridge, web, the demo and the tutorials

launch and bag sit with the libs, not the apps: they are library cores with no user interface of
their own ("Launch = parse, plan, run"; "Bags are a library first") that the roslaunch/rosbag
commands and the rosbag facade wrap, so tools and compat must be able to import them.
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"

ORDER = ["base", "idl", "packages", "wire", "net", "master", "node", "libs", "compat", "tools", "apps"]

#: ninjemys.<name> -> layer (a dotted key such as "bag.record" overrides its package's entry)
LAYERS: dict[str, str] = {
    "": "base",  # the ninjemys package itself (__version__, ROS_DISTRO)
    "errors": "base",
    "names": "base",
    "records": "base",
    "rostime": "base",
    "roshome": "base",
    "commands": "base",
    "paramyaml": "base",
    "paramyaml_emit": "base",
    "paramyaml_pyyaml": "base",
    "share": "base",
    "interrupt": "base",
    "idl": "idl",
    "interfaces": "idl",
    "packages": "packages",
    "wire": "wire",
    "net": "net",
    "master": "master",
    "node": "node",
    "actionlib": "libs",
    "tf2": "libs",
    "message_filters": "libs",
    "dynamic_reconfigure": "libs",
    # the .cfg -> Config.py generator is pure code generation (errors only, like idl's codegen) that
    # catkin_make's build runs: it sits with the packages layer, below the rest of its package
    "dynamic_reconfigure.generator": "packages",
    "laser_geometry": "libs",
    "cv_bridge": "libs",
    "launch": "libs",
    "bag": "libs",
    "tools": "tools",
    "testing": "tools",
    "sim": "apps",
    "nav": "apps",
    "bridge": "apps",
    "web": "apps",
    "demo": "apps",
    "tutorials": "apps",
}


def _is_interface_stub(package: Path, src: Path) -> bool:
    """A top-level package that only exposes message/service/action classes (``std_msgs.msg`` ...):
    its modules import nothing of ours but ninjemys.idl, so it sits with idl."""
    for path in package.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            for name in _imported_names(node, path, src):
                top = name.split(".")[0]
                if top == "ninjemys" and not name.startswith("ninjemys.idl"):
                    return False
                if top != "ninjemys" and top != package.name and (src / top).is_dir():
                    return False
    return True


def _imported_names(node: ast.AST, path: Path, src: Path) -> list[str]:
    """The modules an import statement reaches: ``import a.b`` -> a.b; ``from a import b`` -> a, and
    a.b when that is a module (``from ninjemys import tools``)."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if not isinstance(node, ast.ImportFrom):
        return []
    if node.level:  # relative: resolve against the importing module's package
        package = list(path.relative_to(src).with_suffix("").parts)
        if path.name != "__init__.py":
            package = package[:-1]
        base = package[: len(package) - (node.level - 1)]
        module = ".".join([*base, node.module] if node.module else base)
    else:
        module = node.module or ""
    subs = [f"{module}.{alias.name}" for alias in node.names if _is_module(f"{module}.{alias.name}", src)]
    return [module, *subs]


def _is_module(dotted: str, src: Path) -> bool:
    path = src.joinpath(*dotted.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def _layer_of(dotted: str, src: Path, stubs: set[str]) -> str | None:
    """The layer of a module of ours by its dotted name; None if it is not ours (stdlib, numpy ...)."""
    parts = dotted.split(".")
    if parts[0] != "ninjemys":
        if not (src / parts[0]).is_dir():
            return None
        return "idl" if parts[0] in stubs else "compat"
    rest = parts[1:]
    for depth in range(len(rest), -1, -1):
        layer = LAYERS.get(".".join(rest[:depth]))
        if layer is not None:
            return layer
    return "unknown"


def find_violations(src: Path = SRC) -> list[str]:
    """``file:line: <module> (<layer>) imports <name> (<layer>)`` for every upward import."""
    stubs = {
        p.name for p in src.iterdir() if p.is_dir() and p.name != "ninjemys" and _is_interface_stub(p, src)
    }
    rank = {name: i for i, name in enumerate(ORDER)}
    problems: list[str] = []
    for path in sorted(src.rglob("*.py")):
        if "__pycache__" in path.parts or any(part.endswith(".egg-info") for part in path.parts):
            continue
        parts = list(path.relative_to(src).with_suffix("").parts)
        module = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        own = _layer_of(module, src, stubs)
        where = path.relative_to(src.parent)
        if own == "unknown":
            problems.append(f"{where}:1: {module} is in no layer: add it to LAYERS in tests/test_layering.py")
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for node in sorted(ast.walk(tree), key=lambda n: getattr(n, "lineno", 0)):
            for name in _imported_names(node, path, src):
                layer = _layer_of(name, src, stubs)
                if layer is None or own is None:
                    continue
                if layer == "unknown" or rank[layer] > rank[own]:
                    problems.append(f"{where}:{node.lineno}: {module} ({own}) imports {name} ({layer})")
    return problems


def test_each_layer_imports_only_from_below() -> None:
    problems = find_violations()
    assert not problems, "imports against the layer order (see tests/test_layering.py):\n" + "\n".join(
        problems
    )


def test_the_check_reports_upward_imports_with_file_and_line(tmp_path: Path) -> None:
    src = tmp_path / "src"
    for pkg in ("ninjemys", "ninjemys/node", "ninjemys/tools", "std_msgs", "std_msgs/msg", "rospy"):
        (src / pkg).mkdir(parents=True, exist_ok=True)
        (src / pkg / "__init__.py").write_text("")
    (src / "std_msgs" / "msg" / "__init__.py").write_text("from ninjemys.idl.loader import lazy\n")
    (src / "rospy" / "__init__.py").write_text("from ninjemys.node import Node\n")
    (src / "ninjemys" / "tools" / "rostopic.py").write_text("from ninjemys.node import Node\nimport rospy\n")
    (src / "ninjemys" / "node" / "ok.py").write_text("import os\nfrom std_msgs.msg import String\n")
    (src / "ninjemys" / "node" / "bad.py").write_text(
        "from ninjemys import tools\n\n\ndef f():\n    import ninjemys.tools.rostopic\n    from rospy import init_node\n"
    )
    assert find_violations(src) == [
        "src/ninjemys/node/bad.py:1: ninjemys.node.bad (node) imports ninjemys.tools (tools)",
        "src/ninjemys/node/bad.py:5: ninjemys.node.bad (node) imports ninjemys.tools.rostopic (tools)",
        "src/ninjemys/node/bad.py:6: ninjemys.node.bad (node) imports rospy (compat)",
    ]
