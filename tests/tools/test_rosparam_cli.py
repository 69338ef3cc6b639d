"""rosparam's command line and printing, against Debian's rosparam on the same master.

The fast path (no argparse, no PyYAML) must not change a byte: usage errors, help texts, values of
every type, and `dump`.
"""

from __future__ import annotations

import sys
import xmlrpc.client
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from graph_procs import run_tool  # noqa: E402

from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.testing import run_master  # noqa: E402
from ninjemys.tools import rosparam_args  # noqa: E402

#: values set on the master before the comparisons; printed by `get` and `dump`
PARAMS = {
    "/cli/int": 42,
    "/cli/neg": -7,
    "/cli/big": 2**40,
    "/cli/float": 2.5,
    "/cli/tiny": 1e-10,
    "/cli/huge": 1e17,
    "/cli/bool": True,
    "/cli/text": "hello world",
    "/cli/empty": "",
    "/cli/yes": "yes",
    "/cli/number_text": "12",
    "/cli/colon": "a: b",
    "/cli/lead": " lead",
    "/cli/angle": "deg(90)",
    "/cli/unicode": "héllo wörld \u2603",
    "/cli/multiline": "line one\nline two\n",
    "/cli/long": " ".join(["folded"] * 30),
    "/cli/list": [1, "two", [3.0, False], {"k": "v"}, [], {}],
    "/cli/nested/deep/leaf": "x",
}

GET = [*PARAMS, "/cli", "/cli/nested", "/"]

USAGE_CASES = [
    [],
    ["foo"],
    ["get"],
    ["get", "-x", "/a"],
    ["get", "/a", "/b"],
    ["get", "-h"],
    ["get", "-p"],
    ["get", "--pr", "/cli/text"],
    ["get", "-pv", "/cli/text"],
    ["get", "--", "/cli/text"],
    ["list", "/a", "/b"],
    ["list", "-h"],
    ["list", "-v"],
    ["set"],
    ["set", "/a"],
    ["set", "-t"],
    ["set", "/a", "-t", "/nonexistent/file"],
    ["set", "/a", "-t", "x", "-b", "y"],
    ["set", "-h"],
    ["load"],
    ["load", "-h"],
    ["dump", "a", "b", "c"],
    ["dump", "-h"],
    ["delete"],
    ["delete", "/a", "/b"],
    ["delete", "-h"],
]


@pytest.fixture(scope="module")
def master_uri():
    with run_master() as uri:
        with MasterClient(uri, caller_id="/test") as client:  # sends 2**40 as <i8>, as rospy does
            for name, value in PARAMS.items():
                client.set_param(name, value)
        yield uri


def _same(args: list[str], uri: str) -> None:
    ours = run_tool("rosparam", args, uri, real=False)
    theirs = run_tool("rosparam", args, uri, real=True)
    assert "Traceback" not in ours.stderr
    assert (ours.returncode, ours.stdout, ours.stderr) == (theirs.returncode, theirs.stdout, theirs.stderr)


@pytest.mark.ros1
@pytest.mark.parametrize("args", USAGE_CASES, ids=[" ".join(a) or "(none)" for a in USAGE_CASES])
def test_usage_help_and_errors_match_ros1(master_uri, args):
    _same(args, master_uri)


@pytest.mark.ros1
@pytest.mark.parametrize("name", GET)
def test_get_matches_ros1(master_uri, name):
    _same(["get", name], master_uri)


@pytest.mark.ros1
@pytest.mark.parametrize(
    "args", [["get", "-p", "/cli"], ["get", "-p", "/cli/text"], ["dump"], ["dump", "", "/cli"]]
)
def test_pretty_and_dump_match_ros1(master_uri, args):
    _same(args, master_uri)


@pytest.mark.ros1
def test_set_negative_numbers_and_empty_string(master_uri):
    for args in (["set", "/neg/a", "-5"], ["set", "/neg/b", "-2.5"], ["set", "/neg/c", ""]):
        assert run_tool("rosparam", args, master_uri, real=False).returncode == 0
    proxy = xmlrpc.client.ServerProxy(master_uri)
    assert proxy.getParam("/test", "/neg") == [1, "Parameter [/neg]", {"a": -5, "b": -2.5, "c": ""}]
    _same(["get", "/neg"], master_uri)


def test_parse_reads_common_forms_without_optparse():
    args = rosparam_args.parse("get", ["-p", "/a", "-v"])
    assert (args.command, args.args, args.pretty, args.verbose) == ("get", ["/a"], True, True)
    args = rosparam_args.parse("dump", ["out.yaml", "/ns"])
    assert (args.arg(0), args.arg(1), args.arg(2)) == ("out.yaml", "/ns", None)
    assert rosparam_args.parse("del", ["/x"]).command == "delete"


def test_parse_set_keeps_negative_numbers_as_values():
    args = rosparam_args.parse("set", ["/p", "-5"])
    assert args.args == ["/p", "-5"]
    args = rosparam_args.parse("set", ["-v", "-t", "file.txt", "/p"])
    assert (args.args, args.textfile, args.verbose) == (["/p"], "file.txt", True)


@pytest.mark.parametrize(
    "command,argv,message",
    [
        ("get", [], "invalid arguments. Please specify a parameter name"),
        ("get", ["/a", "/b"], "too many arguments"),
        ("get", ["-q", "/a"], "no such option: -q"),
        ("list", ["-v"], "no such option: -v"),
        ("set", ["/a"], "invalid arguments. Please specify a parameter value"),
        ("load", [], "invalid arguments. Please specify a file name or - for stdin"),
    ],
)
def test_parse_errors_are_ros1_usage_errors(capsys, command, argv, message):
    with pytest.raises(SystemExit) as exc:
        rosparam_args.parse(command, argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("Usage: rosparam ")
    assert err.endswith(f"\nrosparam: error: {message}\n")


@pytest.mark.ros1
def test_load_set_from_files_and_dump_to_file_match_ros1(master_uri, tmp_path):
    """Each tool writes its own namespace from the same files; the trees and dumped files agree."""
    params = tmp_path / "params.yaml"
    params.write_text("gain: 2.5\nangle: deg(180)\nname: ' spaced'\nnested:\n  list: [1, two, {k: v}]\n")
    text = tmp_path / "text.txt"
    text.write_text("<robot name='r'>\n  <link/>\n</robot>\n")
    for real, ns in ((False, "/ours"), (True, "/theirs")):
        for args in (["load", str(params), ns], ["set", "-t", str(text), f"{ns}/description"]):
            result = run_tool("rosparam", args, master_uri, real=real)
            assert result.returncode == 0, result.stderr
        dumped = run_tool("rosparam", ["dump", str(tmp_path / f"{ns[1:]}.yaml"), ns], master_uri, real=real)
        assert dumped.returncode == 0, dumped.stderr
    proxy = xmlrpc.client.ServerProxy(master_uri)
    ours, theirs = proxy.getParam("/test", "/ours")[2], proxy.getParam("/test", "/theirs")[2]
    assert ours == theirs
    assert ours["angle"] == pytest.approx(3.141592653589793) and ours["description"].startswith("<robot")
    assert (tmp_path / "ours.yaml").read_text() == (tmp_path / "theirs.yaml").read_text()
