"""Each layer imports only from the layers below it (docs/architecture.md's layer map), checked with ``ast``.

Every ``import`` and ``from ... import`` in src/ counts, wherever it sits (module top, inside a
function, under ``if TYPE_CHECKING``), and so does ``importlib.import_module("...")`` or
``__import__("...")`` with a literal name: a lazy import is still a dependency. A module may import its
own layer and any layer below; anything else fails with ``file:line``. Three more rules:

- layers that share a floor (a tuple in ``ORDER``: ``sim``, ``nav`` and ``drivers``) are peers and may not import
  each other: the navigation stack ships without the simulator and the simulator without it;
- no app (the floors from ``gateway`` up) imports ``tools``: the commands are a front end, not a
  library; what apps share with them (``commands.entry``, the service probe) lives below;
- every module is in a layer.

The order, bottom to top (``ORDER``; docs/architecture.md draws the same table, a test compares)::

    base       leaf modules every layer may use (errors, names, rostime, roshome, records, paramyaml, interrupt, ...)
    idl        message definitions and classes, and the interface stub packages (src/std_msgs, ...)
    packages   ROS packages on disk: discovery, manifests, shipped executables, catkin workspaces
    wire       ROS 1 serialization, TCPROS framing and headers, XML-RPC encoding (sans-IO)
    net        the node's event loop and the XML-RPC server/client on it; addresses
    serve      HTTP and WebSocket on asyncio, for browsers (serve/)
    master     registrations, parameter server, rosout log format
    node       the client runtime (Node and its parts)
    libs       cores built on Node: actionlib, tf2, message_filters, dynamic_reconfigure,
               laser_geometry, cv_bridge, maps (the map_server format); and the launch and bag cores
               (plan/run, bag files, record/play), which the roslaunch and rosbag commands drive
    compat     the ROS 1 Python facades: every top-level package of src/ other than ninjemys
    tools      the commands (roscore, rostopic, ..., rosout), ninjemys.testing
    gateway    the WebSocket gateway (bridge/): rosbridge v2 and Foxglove for browsers
    sim | nav | drivers
               the simulators, the navigation stack and the device drivers: peers, none imports another
    web        the browser apps (rviz, rqt, the graph page, the simulators' views)
    apps       the demo and the tutorials

launch and bag sit with the libs, not the apps: they are library cores with no user interface of
their own ("Launch = parse, plan, run"; "Bags are a library first") that the roslaunch/rosbag
commands and the rosbag facade wrap, so tools and compat must be able to import them. The web apps
stand above the gateway (they are its clients) and above the simulators (their views draw them).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
ARCHITECTURE_DOC = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"

#: bottom to top; a tuple is one floor of peers that may not import each other
ORDER: list[str | tuple[str, ...]] = [
    "base",
    "idl",
    "packages",
    "wire",
    "net",
    "serve",
    "master",
    "node",
    "libs",
    "compat",
    "tools",
    "gateway",
    ("sim", "nav", "drivers"),
    "web",
    "apps",
]
#: the first floor of the apps: from here up, nothing imports ``tools``
FIRST_APP_FLOOR = "gateway"

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
    "serve": "serve",
    "master": "master",
    "node": "node",
    "actionlib": "libs",
    "tf2": "libs",
    "image_transport": "libs",
    "message_filters": "libs",
    "dynamic_reconfigure": "libs",
    # the .cfg -> Config.py generator is pure code generation (errors only, like idl's codegen) that
    # catkin_make's build runs: it sits with the packages layer, below the rest of its package
    "dynamic_reconfigure.generator": "packages",
    "laser_geometry": "libs",
    "cv_bridge": "libs",
    "robot": "libs",
    "maps": "libs",
    "launch": "libs",
    "bag": "libs",
    "smach": "libs",
    "rostest": "libs",
    "tools": "tools",
    "testing": "tools",
    "bridge": "gateway",
    "zenoh_bridge": "gateway",
    "sim": "sim",
    "nav": "nav",
    "drivers": "drivers",
    "web": "web",
    "demo": "apps",
    "tutorials": "apps",
}


def floors(order: list[str | tuple[str, ...]] = ORDER) -> dict[str, int]:
    """layer -> floor number (peers share one)."""
    return {
        layer: i
        for i, floor in enumerate(order)
        for layer in (floor if isinstance(floor, tuple) else (floor,))
    }


def arrow_problem(own: str, layer: str, order: list[str | tuple[str, ...]] = ORDER) -> str | None:
    """Why a module of layer ``own`` may not import one of ``layer`` (None: it may)."""
    rank = floors(order)
    if layer == "unknown":
        return "a module in no layer"
    if rank[layer] > rank[own]:
        return "a layer above"
    if layer != own and rank[layer] == rank[own]:
        return "a peer"
    if layer == "tools" and rank[own] >= rank[FIRST_APP_FLOOR]:
        return "the commands (no app imports tools)"
    return None


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
    if isinstance(node, ast.Call) and _is_import_call(node.func) and node.args:
        # importlib.import_module("ninjemys.x") / __import__("ninjemys.x"): an import by another name
        first = node.args[0]
        return [first.value] if isinstance(first, ast.Constant) and isinstance(first.value, str) else []
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


def _is_import_call(func: ast.expr) -> bool:
    if isinstance(func, ast.Name):
        return func.id in ("__import__", "import_module")
    return isinstance(func, ast.Attribute) and func.attr == "import_module"


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
                why = arrow_problem(own, layer)
                if why is not None:
                    problems.append(
                        f"{where}:{node.lineno}: {module} ({own}) imports {name} ({layer}): {why}"
                    )
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
        "src/ninjemys/node/bad.py:1: ninjemys.node.bad (node) imports ninjemys.tools (tools): a layer above",
        "src/ninjemys/node/bad.py:5: ninjemys.node.bad (node) imports ninjemys.tools.rostopic (tools): a layer above",
        "src/ninjemys/node/bad.py:6: ninjemys.node.bad (node) imports rospy (compat): a layer above",
    ]


_TOP = "{imp}\n"
_LAZY = "def f():\n    {imp}\n"
_TYPING = "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n    {imp}\n"


@pytest.mark.parametrize("form", [_TOP, _LAZY, _TYPING], ids=["top", "function", "type_checking"])
@pytest.mark.parametrize(
    ("module", "imp", "why"),
    [
        # the arrows of issue 22, each as it stood in the tree before the floor plan
        ("bridge/server.py", "from ninjemys.web.app import STATIC_DIR", "a layer above"),
        ("bridge/server.py", "from ninjemys.web.http import HttpServer", "a layer above"),
        ("sim/view.py", "from ninjemys.web.app import WebApp", "a layer above"),
        ("nav/amcl.py", "from ninjemys.sim.mapfile import GridMap", "a peer"),
        ("sim/world_to_map.py", "from ninjemys.nav.amcl import GridMap", "a peer"),
        (
            "bridge/graph.py",
            "from ninjemys.tools.rosservice import probe",
            "the commands (no app imports tools)",
        ),
        ("web/rviz.py", "from ninjemys.tools.cli import entry", "the commands (no app imports tools)"),
        ("sim/mimic.py", "import ninjemys.tools.cli", "the commands (no app imports tools)"),
        ("demo.py", "from ninjemys.testing import free_port", "the commands (no app imports tools)"),
        ("net/addresses.py", "from ninjemys.serve import http", "a layer above"),
        ("serve/http.py", "from ninjemys.bridge import server", "a layer above"),
    ],
)
def test_the_check_fails_on_each_arrow_of_issue_22(
    tmp_path: Path, form: str, module: str, imp: str, why: str
) -> None:
    src = tmp_path / "src"
    for pkg in (
        "ninjemys",
        *(f"ninjemys/{p}" for p in ("bridge", "web", "sim", "nav", "tools", "serve", "net")),
    ):
        (src / pkg).mkdir(parents=True, exist_ok=True)
        (src / pkg / "__init__.py").write_text("")
    for stub in (
        "web/app.py",
        "web/http.py",
        "web/rviz.py",
        "sim/mapfile.py",
        "nav/amcl.py",
        "tools/rosservice.py",
        "tools/cli.py",
        "testing.py",
        "serve/http.py",
        "bridge/server.py",
        "net/addresses.py",
    ):
        (src / "ninjemys" / stub).write_text("")
    assert find_violations(src) == []
    (src / "ninjemys" / module).write_text(form.format(imp=imp))
    problems = find_violations(src)
    assert problems, f"{module}: {imp} was not caught"
    for problem in problems:  # ``from a import b`` reports a and a.b
        assert problem.startswith(f"src/ninjemys/{module}:") and problem.endswith(f": {why}"), problem


def test_peers_and_the_apps_rule_on_synthetic_layers() -> None:
    order: list[str | tuple[str, ...]] = ["base", "tools", "gateway", ("sim", "nav"), "web"]
    assert arrow_problem("web", "gateway", order) is None
    assert arrow_problem("web", "sim", order) is None
    assert arrow_problem("sim", "gateway", order) is None
    assert arrow_problem("gateway", "web", order) == "a layer above"
    assert arrow_problem("sim", "nav", order) == "a peer"
    assert arrow_problem("nav", "sim", order) == "a peer"
    assert arrow_problem("web", "tools", order) == "the commands (no app imports tools)"
    assert arrow_problem("tools", "tools", order) is None
    assert arrow_problem("sim", "unknown", order) == "a module in no layer"


def _doc_table() -> list[tuple[str, str]]:
    """(layer, packages) rows of the layer map in docs/architecture.md, bottom floor first."""
    text = ARCHITECTURE_DOC.read_text(encoding="utf-8")
    table = text.split("<!-- layer map -->", 2)[1]
    rows = []
    for line in table.splitlines():
        cells = [
            c.strip().replace("\0", "|") for c in line.replace("\\|", "\0").strip().strip("|").split("|")
        ]
        if len(cells) >= 3 and cells[0].isdigit():
            rows.append((cells[1], cells[2]))
    return rows


def test_the_layer_map_in_docs_says_what_order_says() -> None:
    rows = _doc_table()
    expected = [" | ".join(f) if isinstance(f, tuple) else f for f in ORDER]
    assert [layer.replace("`", "") for layer, _ in rows] == expected
    # every package the doc names sits in the layer of its row; every LAYERS entry is named in the doc
    named: dict[str, str] = {}
    for layer, packages in rows:
        peers = [p.strip() for p in layer.replace("`", "").split("|")]
        for pkg in re.findall(r"`ninjemys\.([a-z_0-9.]*)`", packages):
            named[pkg] = LAYERS.get(pkg, "?")
            assert LAYERS.get(pkg) in peers, (
                f"docs/architecture.md puts ninjemys.{pkg} in {layer}, LAYERS in {LAYERS.get(pkg)}"
            )
    missing = sorted(k for k in LAYERS if k and "." not in k and k not in named)
    assert not missing, f"docs/architecture.md's layer map does not name: {missing}"


def test_a_literal_dynamic_import_counts(tmp_path: Path) -> None:
    src = tmp_path / "src"
    for pkg in ("ninjemys", "ninjemys/sim", "ninjemys/web"):
        (src / pkg).mkdir(parents=True, exist_ok=True)
        (src / pkg / "__init__.py").write_text("")
    (src / "ninjemys" / "web" / "app.py").write_text("")
    (src / "ninjemys" / "sim" / "view.py").write_text(
        'import importlib\n\n\ndef f():\n    return importlib.import_module("ninjemys.web.app")\n'
    )
    (src / "ninjemys" / "sim" / "other.py").write_text('def g():\n    return __import__("ninjemys.web")\n')
    problems = find_violations(src)
    assert problems == [
        "src/ninjemys/sim/other.py:2: ninjemys.sim.other (sim) imports ninjemys.web (web): a layer above",
        "src/ninjemys/sim/view.py:5: ninjemys.sim.view (sim) imports ninjemys.web.app (web): a layer above",
    ]
