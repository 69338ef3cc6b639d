"""Runs Debian's real roslaunch query functions for a batch of queries, in one /usr/bin/python3 process.

Input (argv[1]): JSON list of {"kind": nodes|args|find|dump|rosargs, "files": [...], "argv": [...],
"node": name}. Output (stdout): JSON list of {"stdout": str, "code": int}, one per query. Calling the
functions the roslaunch CLI calls (with sys.argv set as the CLI would have it) gives the CLI's exact
output without paying roslaunch's start-up cost per query.
"""

import contextlib
import io
import json
import sys

import roslaunch.arg_dump
import roslaunch.config
import roslaunch.node_args
import roslaunch.param_dump

# load_config_default() first loads roscore.xml, whose <param command="rosversion ..."/> runs two
# subprocesses per query (seconds on a busy machine). Core nodes and core params never appear in
# the outputs compared here (--nodes, --args, --find-node, --ros-args; --dump-params skips it), so
# the oracle skips that step.
roslaunch.config.load_roscore = lambda *args, **kwargs: None


def run(query):
    files, argv, node = query["files"], query["argv"], query.get("node")
    sys.argv = ["roslaunch", *files, *argv]
    out, err = io.StringIO(), io.StringIO()
    code = 0
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            kind = query["kind"]
            if kind == "nodes":
                roslaunch.node_args.print_node_list(files)
            elif kind == "args":
                roslaunch.node_args.print_node_args(node, files)
            elif kind == "find":
                roslaunch.node_args.print_node_filename(node, files)
            elif kind == "dump":
                if not roslaunch.param_dump.dump_params(files):
                    code = 1
            elif kind == "rosargs":
                roslaunch.arg_dump.dump_args(files)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
        except Exception as exc:  # noqa: BLE001 - reported to the test as a failure code
            err.write(f"{type(exc).__name__}: {exc}")
            code = 2
    return {"stdout": out.getvalue(), "stderr": err.getvalue(), "code": code}


def run_all(case):
    """Every query for one launch file: nodes, dump, rosargs, then args and find for each node."""
    files, argv = case["files"], case["argv"]
    answers = {k: run({"kind": k, "files": files, "argv": argv}) for k in ("nodes", "dump", "rosargs")}
    for node in [n for n in answers["nodes"]["stdout"].splitlines() if n]:
        for kind in ("args", "find"):
            answers[f"{kind} {node}"] = run({"kind": kind, "files": files, "argv": argv, "node": node})
    return answers


if __name__ == "__main__":
    queries = json.loads(sys.argv[1])
    print(json.dumps([run_all(q) if q["kind"] == "all" else run(q) for q in queries]))
