"""The threading table (ninjemys.node.threads) against the code: thread names, locks, queues, callbacks."""

from __future__ import annotations

import ast
import threading
from pathlib import Path

from node_harness import wait_until
from node_msgs import String

from ninjemys.idl.loader import get_service_class
from ninjemys.node import threads

SRC = Path(__file__).resolve().parents[2] / "src"
#: where the core starts threads and creates its locks and queues
THREAD_SOURCES = [
    SRC / "ninjemys" / "node",
    SRC / "ninjemys" / "net",
    SRC / "ninjemys" / "master",
    SRC / "rospy",
    SRC / "ninjemys" / "nav" / "move_base_node.py",
    SRC / "ninjemys" / "sim",
    SRC / "ninjemys" / "web" / "gazebo_ros.py",
]
LOCK_SOURCES = [
    SRC / "ninjemys" / "node",
    SRC / "ninjemys" / "net",
    SRC / "ninjemys" / "master" / "client.py",
    SRC / "ninjemys" / "nav" / "move_base_node.py",
]
_SYNC = {"Lock", "RLock", "Condition", "Event", "local", "deque"}


def _files(roots: list[Path]) -> list[Path]:
    out: list[Path] = []
    for root in roots:
        out.extend([root] if root.is_file() else sorted(root.rglob("*.py")))
    return out


def _name_prefix(node: ast.expr) -> str | None:
    """The fixed part of a thread name given as a literal or an f-string; None for a variable."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr) and node.values and isinstance(node.values[0], ast.Constant):
        return str(node.values[0].value)
    return None


def _callee(call: ast.Call) -> str:
    func = call.func
    return func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""


def started_thread_names() -> list[tuple[str, str]]:
    """(file:line, name prefix) of every thread the core starts with a literal name."""
    found: list[tuple[str, str]] = []
    for path in _files(THREAD_SOURCES):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                names: list[ast.expr] = []
                if _callee(node) in ("Thread", "Timer"):
                    names = [kw.value for kw in node.keywords if kw.arg == "name"]
                elif _callee(node) == "start_thread" and len(node.args) >= 2:
                    names = [node.args[1]]
                for expr in names:
                    prefix = _name_prefix(expr)
                    if prefix is not None:
                        found.append((f"{path.relative_to(SRC)}:{node.lineno}", prefix))
            elif isinstance(node, ast.ClassDef) and any(
                isinstance(n, ast.Call) and _callee(n) == "Thread" for n in ast.walk(node)
            ):
                # a class that starts a thread named by its ``name`` argument: that argument's default
                for init in (n for n in node.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"):
                    args = init.args.args[len(init.args.args) - len(init.args.defaults) :]
                    for arg, default in zip(args, init.args.defaults, strict=True):
                        prefix = _name_prefix(default) if arg.arg == "name" else None
                        if prefix is not None:
                            found.append((f"{path.relative_to(SRC)}:{init.lineno}", prefix))
    return found


def sync_attributes() -> set[str]:
    """``module:Class.attr`` (or ``module:name``) of every lock, event, thread-local and deque made."""
    found: set[str] = set()
    for path in _files(LOCK_SOURCES):
        module = ".".join(path.relative_to(SRC).with_suffix("").parts)
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for top in tree.body:
            classes = [top] if isinstance(top, ast.ClassDef) else []
            if isinstance(top, ast.Assign | ast.AnnAssign) and _makes_sync(top.value):
                targets = top.targets if isinstance(top, ast.Assign) else [top.target]
                found.update(f"{module}:{t.id}" for t in targets if isinstance(t, ast.Name))
            for cls in classes:
                for node in ast.walk(cls):
                    if isinstance(node, ast.Assign | ast.AnnAssign) and _makes_sync(node.value):
                        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                        for t in targets:
                            if (
                                isinstance(t, ast.Attribute)
                                and isinstance(t.value, ast.Name)
                                and t.value.id == "self"
                            ):
                                found.add(f"{module}:{cls.name}.{t.attr}")
    return found


def _makes_sync(value: ast.expr | None) -> bool:
    return isinstance(value, ast.Call) and _callee(value) in _SYNC


def test_every_thread_the_core_starts_is_in_the_table() -> None:
    prefixes = {t.prefix for t in threads.THREADS}
    started = started_thread_names()
    assert {name for _, name in started} >= {
        "ninjemys-io",
        "sub:",
        "srv:",
        "reg:",
        "timer:",
        "ninjemys-timer",
    }
    missing = [f"{where}: thread {name!r}" for where, name in started if name not in prefixes]
    assert not missing, "threads missing from ninjemys.node.threads.THREADS:\n" + "\n".join(missing)


def test_every_lock_and_queue_has_a_row_and_every_row_exists() -> None:
    in_code = sync_attributes()
    rows = {r.where for r in threads.RESOURCES if r.kind in ("lock", "event", "queue")}
    scanned = {".".join(p.relative_to(SRC).with_suffix("").parts) for p in _files(LOCK_SOURCES)}
    rows_here = {w for w in rows if w.split(":")[0] in scanned}
    assert not in_code - rows_here, f"not in ninjemys.node.threads.RESOURCES: {sorted(in_code - rows_here)}"
    assert not rows_here - in_code, f"rows naming nothing in the code: {sorted(rows_here - in_code)}"
    owners = {t.name for t in threads.THREADS} | {threads.USER}
    for row in threads.RESOURCES:
        assert row.owner and row.others, row.where
        named = row.owner.split(" (")[0].split(" / ")[0]
        assert named in owners or not named.startswith(("ninjemys", "sub:", "srv:", "reg:")), row.owner


def test_live_nodes_run_only_tabled_threads_and_callbacks_where_the_table_says(make_node) -> None:
    before = set(threading.enumerate())
    node = make_node("threads_a", params={"gain": 1})
    peer = make_node("threads_b")
    seen: dict[str, str] = {}
    got = threading.Event()

    def remember(kind: str) -> None:
        seen[kind] = threading.current_thread().name
        if len(seen) == 4:
            got.set()

    node.subscriber("chatter", String, lambda msg: remember("subscriber"))
    AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")
    node.service("~add", AddTwoInts, lambda req: (remember("service"), AddTwoInts._response_class(sum=0))[1])
    node.timer(0.01, lambda event: remember("timer"), oneshot=True)
    node.subscribe_param("~gain", lambda key, value: remember("parameter"))
    pub = peer.publisher("chatter", String)
    assert wait_until(lambda: pub.get_num_connections() >= 1)
    pub.publish(String("x"))
    peer.service_proxy("/threads_a/add", AddTwoInts)(a=1, b=2)
    peer.set_param("/threads_a/gain", 2)
    assert got.wait(10), seen
    by_user_code = {t.name.split("<")[0]: t.user_code for t in threads.THREADS}
    expected = {
        "subscriber": "sub:",
        "service": "srv:",
        "timer": "timer:",
        "parameter": "param-update",
    }
    for kind, prefix in expected.items():
        assert seen[kind].startswith(prefix), (kind, seen[kind])
        assert kind in by_user_code[prefix], (kind, prefix)
    assert threads.LOOP not in seen.values()  # the loop never runs user code
    prefixes = tuple(t.prefix for t in threads.THREADS)
    extra = [t.name for t in set(threading.enumerate()) - before if not t.name.startswith(prefixes)]
    assert not extra, f"threads not in the table: {extra}"
