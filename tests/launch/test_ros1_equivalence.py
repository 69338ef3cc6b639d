"""The main acceptance test of the launch plan: our query output equals Debian's roslaunch's.

For every launch file of the corpus (tests/launch/data/pkgs, which covers every tag and
substitution) and several argument sets: ``--nodes``, ``--dump-params``, ``--ros-args``, and
``--args`` / ``--find-node`` for every node print exactly what real roslaunch prints.
"""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
from pathlib import Path

import pytest

from ninjemys.errors import NinjemysError
from ninjemys.testing import ROS1_PYTHON, ros1_env
from ninjemys.tools import roslaunch

from .conftest import PKGS

ORACLE = Path(__file__).parent / "ros1_oracle.py"

CASES = [
    ("corpus_a/launch/everything.launch", ["robot:=otter"]),
    ("corpus_a/launch/everything.launch", ["with_group:=false", "use_sim:=true"]),
    ("corpus_a/launch/included.launch", ["who:=somebody"]),
    ("corpus_a/launch/eval.launch", ["x:=7", "flag:=false"]),
    ("corpus_b/launch/animals.launch", ["dolphin_msg:=Hi"]),
    ("corpus_b/launch/namespaces.launch", []),
    ("corpus_b/launch/pubsub.launch", []),
    ("corpus_b/launch/find_paths.launch", []),
]


def ours(query: dict) -> dict:
    """Run our roslaunch CLI in-process for one query; same shape as the oracle's answers."""
    flag = {
        "nodes": ["--nodes"],
        "dump": ["--dump-params"],
        "rosargs": ["--ros-args"],
        "args": ["--args", query.get("node", "")],
        "find": ["--find-node", query.get("node", "")],
    }[query["kind"]]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = roslaunch.main([*flag, *query["files"], *query["argv"]])
        except NinjemysError as exc:
            err.write(str(exc))
            code = 1
    return {"stdout": out.getvalue(), "stderr": err.getvalue(), "code": code}


def oracle(queries: list[dict], env: dict[str, str]) -> list[dict]:
    full_env = ros1_env(
        env["ROS_MASTER_URI"], ROS_PACKAGE_PATH=env["ROS_PACKAGE_PATH"], NJ_CORPUS_USER="tester"
    )
    full_env.pop("NJ_CORPUS_HOME", None)
    proc = subprocess.run(
        [ROS1_PYTHON, str(ORACLE), json.dumps(queries)],
        env=full_env,
        capture_output=True,
        text=True,
        timeout=90,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


@pytest.fixture(scope="module")
def real_answers() -> list[dict]:
    """Real roslaunch's answers for every case, computed in one process (its import costs seconds)."""
    env = {"ROS_PACKAGE_PATH": str(PKGS), "ROS_MASTER_URI": "http://localhost:11311"}
    cases = [{"kind": "all", "files": [str(PKGS / launch)], "argv": argv} for launch, argv in CASES]
    missing = {"kind": "nodes", "files": [str(PKGS / "corpus_a/launch/included.launch")], "argv": []}
    return oracle([*cases, missing], env)


@pytest.mark.ros1
@pytest.mark.parametrize(
    "case", range(len(CASES)), ids=[f"{c[0]}-{'-'.join(c[1]) or 'defaults'}" for c in CASES]
)
def test_queries_match_real_roslaunch(
    case: int, real_answers: list[dict], corpus_env: dict[str, str]
) -> None:
    launch, argv = CASES[case]
    files = [str(PKGS / launch)]
    expected_all = real_answers[case]
    assert expected_all["nodes"]["stdout"].strip(), f"real roslaunch listed no nodes for {launch}"
    assert len(expected_all) > 3
    for key, expected in expected_all.items():
        kind, _, node = key.partition(" ")
        query = {"kind": kind, "files": files, "argv": argv, "node": node}
        assert expected["code"] == 0, f"real roslaunch failed on {key}: {expected}"
        got = ours(query)
        assert got["code"] == 0, f"ours failed on {key}: {got['stderr']}"
        assert got["stdout"] == expected["stdout"], f"{key} differs for {launch}"


@pytest.mark.ros1
def test_missing_arg_fails_in_both(real_answers: list[dict], corpus_env: dict[str, str]) -> None:
    expected = real_answers[-1]
    files = [str(PKGS / "corpus_a/launch/included.launch")]
    got = ours({"kind": "nodes", "files": files, "argv": []})
    assert expected["code"] != 0 and got["code"] != 0
    assert "arg 'who' is not set" in got["stderr"]
    assert got["stdout"] == ""
