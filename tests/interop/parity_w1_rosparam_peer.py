"""rosparam's Python API, printed as JSON (run under either interpreter against a fresh master):
loading YAML files and strings (namespaces, angles, binary, several documents), uploading, get/set/
delete/list/dump, and the errors bad input raises."""

import contextlib
import io
import json
import os
import tempfile
from xmlrpc.client import Binary

import yaml

import rosgraph
import rosparam


def attempt(f, *args, **kw):
    try:
        return ["ok", plain(f(*args, **kw))]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


def plain(x):
    if isinstance(x, Binary):
        return ["binary", x.data.hex()]
    if isinstance(x, bytes):
        return ["binary", x.hex()]
    if isinstance(x, dict):
        return {k: plain(v) for k, v in sorted(x.items())}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    return x


def yaml_error(f, *args):
    """ROS 1 lets PyYAML's exception through; ours is a yaml.YAMLError too (and names the place)."""
    try:
        f(*args)
    except yaml.YAMLError:
        return "yaml.YAMLError"
    return "no error"


def printed(f, *args, **kw):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        r = attempt(f, *args, **kw)
    return [buf.getvalue(), r]


DOCS = """
a: 1
b: {c: two, d: [1, 2.5]}
angle: !degrees 180
rad: rad(pi/2)
blob: !!binary aGVsbG8=
---
_ns: sub
x: true
---
_ns: /abs
y: 3
"""
tmp = tempfile.mkdtemp()
path = os.path.join(tmp, "p.yaml")
with open(path, "w") as f:
    f.write(DOCS)

out = {"load": {}, "server": {}, "errors": {}}
out["load"]["file"] = printed(rosparam.load_file, path, default_namespace="/w1/", verbose=True)
out["load"]["str"] = attempt(rosparam.load_str, "k: v", "f.yaml")
out["load"]["str_ns"] = attempt(rosparam.load_str, "k: v", "f.yaml", default_namespace="/ns/")
out["load"]["missing"] = attempt(rosparam.load_file, os.path.join(tmp, "none.yaml"))
out["load"]["bad_yaml"] = yaml_error(rosparam.load_str, "a: [1,", "bad.yaml")

for doc, ns in rosparam.load_file(path, default_namespace="/w1/"):
    if doc:
        rosparam.upload_params(ns, doc)
out["server"]["tree"] = plain(rosparam.get_param("/w1"))
out["server"]["abs"] = attempt(rosparam.get_param, "/abs")
out["server"]["list"] = rosparam.list_params("/w1")
out["server"]["list_rel"] = rosparam.list_params("w1/b")
out["server"]["set"] = printed(rosparam.set_param, "/w1/s", "[1, {k: 2}]", verbose=True)
out["server"]["set_dict"] = printed(rosparam.set_param, "/w1/b", "{e: 3}")
out["server"]["after_set"] = plain(rosparam.get_param("/w1/b"))
out["server"]["set_raw"] = printed(rosparam.set_param_raw, "/w1/raw", {"z": 1.5}, verbose=True)
out["server"]["dump"] = printed(rosparam.dump_params, None, "/w1/b")
dump_path = os.path.join(tmp, "dump.yaml")
rosparam.dump_params(dump_path, "/w1/b", verbose=False)
with open(dump_path) as f:
    out["server"]["dump_file"] = f.read()
out["server"]["print"] = printed(rosparam.print_params, {"a": 1, "b": {"c": 2}}, "/ns")
out["server"]["delete"] = printed(rosparam.delete_param, "/w1/a", verbose=True)
out["server"]["after_delete"] = rosparam.list_params("/w1")
out["server"]["caller"] = rosparam.get_param_server().caller_id == f"/rosparam-{os.getpid()}"

out["errors"]["get_missing"] = attempt(rosparam.get_param, "/w1/none")
out["errors"]["delete_missing"] = attempt(rosparam.delete_param, "/w1/none")
out["errors"]["upload_global"] = attempt(rosparam.upload_params, "/", 5)
out["errors"]["set_bad_yaml"] = yaml_error(rosparam.set_param, "/w1/q", "[1,")
out["errors"]["int_keys"] = attempt(rosparam.set_param_raw, "/w1/q", {1: 2})
out["errors"]["classes"] = [issubclass(rosparam.RosParamIOException, rosparam.RosParamException)]
rosparam.yamlmain(["rosparam", "set", "/w1/cli", "[1, two]"])
out["server"]["yamlmain"] = rosparam.get_param("/w1/cli")
try:
    rosparam.yamlmain(["rosparam", "get", "/w1/none_here"])
except SystemExit as exc:
    out["server"]["yamlmain_error"] = exc.code
rosparam.delete_param("/")
out["errors"]["deleted_all"] = [
    n
    for n in rosgraph.Master("/x").getParamNames()
    if not n.startswith("/run_id")
    and not n.startswith("/roslaunch")
    and not n.startswith("/rosversion")
    and not n.startswith("/rosdistro")
]
print(json.dumps(out, sort_keys=True).replace(tmp, "TMP"))
