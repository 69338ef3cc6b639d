"""``roslaunch``: ROS 1's command line over ninjemys' parse -> plan -> run launcher.

Forms: ``roslaunch PKG FILE.launch [arg:=v ...]``, ``roslaunch path/file.launch [...]``,
``roslaunch -`` (XML on stdin), and, because the tutorials teach it, ``roslaunch PKG EXECUTABLE``,
which runs the executable as one node (as rosrun would, with a master auto-started) and says so.
Query options (``--nodes``, ``--args``, ``--find-node``, ``--dump-params``, ``--files``,
``--ros-args``) print exactly what ROS 1 prints and start nothing.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

from ninjemys.errors import LaunchError, NinjemysError
from ninjemys.launch import queries
from ninjemys.launch.launcher import LaunchOptions, LaunchSession
from ninjemys.launch.plan import LaunchPlan, NodeSpec
from ninjemys.launch.runner import DEFAULT_SIGINT_TIMEOUT, DEFAULT_SIGTERM_TIMEOUT
from ninjemys.launch.xml import load_launch
from ninjemys.names import is_remap_arg
from ninjemys.packages.discovery import PackageIndex
from ninjemys.packages.executables import find_executable
from ninjemys.tools.cli import entry, error

USAGE = """roslaunch [options] [package] <filename> [arg_name:=value...]
       roslaunch [options] <filename> [<filename>...] [arg_name:=value...]

If <filename> is a single dash ('-'), launch XML is read from standard input."""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="roslaunch", usage=USAGE, add_help=True)
    p.add_argument(
        "--files",
        action="store_true",
        help="Print list files loaded by launch file, including launch file itself",
    )
    p.add_argument(
        "--args", dest="node_args", metavar="NODE_NAME", help="Print command-line arguments for node"
    )
    p.add_argument("--nodes", action="store_true", help="Print list of node names in launch file")
    p.add_argument("--find-node", metavar="NODE_NAME", help="Find launch file that node is defined in")
    p.add_argument("-c", "--child", metavar="NAME", help="accepted for compatibility (no child processes)")
    p.add_argument("--local", action="store_true", help="Do not launch remote nodes")
    p.add_argument("--screen", action="store_true", help="Force output of all local nodes to screen")
    p.add_argument("--required", action="store_true", help="Force all nodes to be required")
    p.add_argument("--log", action="store_true", help="Force output of all local nodes to log")
    p.add_argument(
        "--prefix-output",
        action="store_true",
        default=os.environ.get("NINJEMYS_LAUNCH_PREFIX", "") not in ("", "0"),
        help="print each line of the nodes' output behind [process-name] (also: NINJEMYS_LAUNCH_PREFIX=1); "
        "by default output passes through unchanged, as in ROS 1",
    )
    p.add_argument("-u", "--server_uri", help="accepted for compatibility")
    p.add_argument("--run_id", help="accepted for compatibility (the master's /run_id is used)")
    p.add_argument("--wait", action="store_true", help="wait for master to start before launching")
    p.add_argument("-p", "--port", type=int, help="master port. Only valid if master is launched")
    p.add_argument("--core", action="store_true", help="Launch core services only")
    p.add_argument("--pid", dest="pid_fn", help="write the roslaunch pid to filename")
    p.add_argument("-v", action="store_true", dest="verbose", help="verbose printing")
    p.add_argument("--no-summary", action="store_true", help="hide summary printing")
    p.add_argument(
        "--dump-params", action="store_true", help="Dump parameters of all roslaunch files to stdout"
    )
    p.add_argument("--skip-log-check", action="store_true", help="accepted (no log size check is done)")
    p.add_argument(
        "--ros-args", action="store_true", help="Display command-line arguments for this launch file"
    )
    p.add_argument("--disable-title", action="store_true", help="accepted for compatibility")
    p.add_argument("-w", "--numworkers", type=int, help="accepted for compatibility")
    p.add_argument("-t", "--timeout", type=float, help="accepted for compatibility")
    p.add_argument("--master-logger-level", help="accepted for compatibility")
    p.add_argument(
        "--sigint-timeout",
        type=float,
        default=DEFAULT_SIGINT_TIMEOUT,
        help=f"seconds from SIGINT to SIGTERM at shutdown (default {DEFAULT_SIGINT_TIMEOUT}; "
        "per node: <node sigint_timeout=...>)",
    )
    p.add_argument(
        "--sigterm-timeout",
        type=float,
        default=DEFAULT_SIGTERM_TIMEOUT,
        help=f"seconds from SIGTERM to SIGKILL (default {DEFAULT_SIGTERM_TIMEOUT})",
    )
    p.add_argument("positional", nargs="*", help=argparse.SUPPRESS)
    return p


def _find_in_package(package: str, name: str) -> Path | None:
    root = PackageIndex.from_environment().find(package).path
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        if name in filenames:
            return Path(dirpath) / name
    return None


def _executable_plan(package: str, executable: str, args: list[str]) -> LaunchPlan:
    """``roslaunch PKG EXECUTABLE``: a one-node plan, output to screen."""
    base = re.sub(r"\W", "_", Path(executable).stem) or "node"
    if not base[0].isalpha():
        base = "n" + base
    remaps = [tuple(a.split(":=", 1)) for a in args if is_remap_arg(a) and not a.startswith("_")]
    name = next((dst for src, dst in remaps if src == "__name"), base)
    plain = [a for a in args if not is_remap_arg(a)]
    private = [a for a in args if is_remap_arg(a) and a.startswith("_") and not a.startswith("__")]
    node = NodeSpec(
        package=package,
        type=executable,
        name=name,
        args=" ".join([*plain, *private]),
        remap_args=[(s, d) for s, d in remaps if not s.startswith("__")],
        output="screen",
        filename="<command line>",
    )
    return LaunchPlan(nodes=[node])


def resolve_files(positional: list[str]) -> tuple[list[str], list[str], tuple[str, str] | None]:
    """(launch files, arg:=value args, (pkg, executable) for the rosrun form) from the positionals."""
    args = [a for a in positional if is_remap_arg(a)]
    rest = [a for a in positional if not is_remap_arg(a)]
    if not rest:
        raise LaunchError("you must specify at least one input file")
    if rest == ["-"]:
        return ["-"], args, None
    if all(os.path.isfile(f) for f in rest):
        return rest, args, None
    if len(rest) == 2 and not os.path.isfile(rest[0]):
        package, name = rest
        found = _find_in_package(package, name)
        if found is not None and (
            found.suffix in (".launch", ".xml", ".test") or not os.access(found, os.X_OK)
        ):
            return [str(found)], args, None
        try:
            find_executable(PackageIndex.from_environment().find(package), name)
        except NinjemysError:
            raise LaunchError(
                f"[{name}] is neither a launch file in package [{package}] nor is [{package}] a launch file name"
            ) from None
        return [], args, (package, name)
    missing = next(f for f in rest if not os.path.isfile(f))
    raise LaunchError(f"The following input files do not exist: {missing}")


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    opts = _parser().parse_args(argv)
    if opts.core:
        os.execv(
            sys.executable,
            [sys.executable, "-m", "ninjemys.tools.roscore", *(["-p", str(opts.port)] if opts.port else [])],
        )
    files, launch_args, rosrun_form = resolve_files(opts.positional)
    if rosrun_form is not None:
        package, executable = rosrun_form
        print(
            f"roslaunch: [{executable}] is an executable of package [{package}], not a launch file: "
            f"running it as 'rosrun {package} {executable}' would, with a master if none is running",
            file=sys.stderr,
        )
        plan = _executable_plan(package, executable, launch_args)
        files = []
    else:
        xml_text = sys.stdin.read() if files == ["-"] else None
        file_list = [] if files == ["-"] else files
        plan = load_launch(file_list, argv=launch_args, xml_text=xml_text, args_only=opts.ros_args)
        if opts.ros_args:
            print(queries.ros_args(plan))
            return 0
    assert plan is not None
    query = opts.nodes or opts.node_args or opts.find_node or opts.dump_params or opts.files
    if query:
        for warning in plan.warnings:
            print(f"WARNING: {warning}", file=sys.stderr)
    if opts.nodes:
        print(queries.node_list(plan))
        return 0
    if opts.node_args:
        try:
            print(queries.node_args(plan, opts.node_args, files))
        except LaunchError as exc:
            print(str(exc), file=sys.stderr)
            return 1
        return 0
    if opts.find_node:
        found = queries.find_node(plan, opts.find_node)
        if found is None:
            name = queries.script_resolve_name(opts.find_node)
            print(
                f"ERROR: cannot find node named [{name}]. Run \n\troslaunch --nodes <files>\nto see list of node names.",
                file=sys.stderr,
            )
            return 1
        print(found)
        return 0
    if opts.dump_params:
        sys.stdout.write(queries.dump_params(plan))
        return 0
    if opts.files:
        print("\n".join(os.path.abspath(f) for f in dict.fromkeys(plan.files)))
        return 0
    if opts.pid_fn:
        Path(opts.pid_fn).write_text(f"{os.getpid()}\n", encoding="utf-8")
    options = LaunchOptions(
        screen=opts.screen,
        log=opts.log,
        port=opts.port,
        wait=opts.wait,
        required=opts.required,
        local_only=opts.local,
        no_summary=opts.no_summary,
        sigint_timeout=opts.sigint_timeout,
        sigterm_timeout=opts.sigterm_timeout,
        prefix_output=opts.prefix_output,
    )
    try:
        return LaunchSession(plan, options).run()
    except KeyboardInterrupt:
        error("interrupted before the launch started")
        return 1


console_main = entry(main)
