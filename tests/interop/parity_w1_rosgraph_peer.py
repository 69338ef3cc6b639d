"""rosgraph as ROS 1 programs use it, printed as JSON (run under either interpreter, ROS_MASTER_URI
set): the name functions on legal and bad inputs, the master handle's answers and errors, the
network helpers and the handshake header codec."""

import json
import os

import rosgraph
import rosgraph.masterapi
import rosgraph.names as n
import rosgraph.network as net


def attempt(f, *args):
    try:
        return ["ok", f(*args)]
    except Exception as exc:  # noqa: BLE001
        return ["raise", [type(exc).__name__], str(exc)]


out = {"names": {}, "master": {}, "network": {}}
NAMES = ["", "/", "foo", "/foo", "~foo", "foo/bar", "/foo//bar/", "~", "1bad", "a-b", "/a/b/c", "foo/"]
for name in NAMES:
    for fn in (
        "is_global",
        "is_private",
        "namespace",
        "canonicalize_name",
        "is_legal_name",
        "is_legal_base_name",
    ):
        out["names"][f"{fn}({name!r})"] = attempt(getattr(n, fn), name)
    out["names"][f"make_global_ns({name!r})"] = attempt(n.make_global_ns, name)
    for ns in ("", "/", "/ns", "ns/", "/a/b/"):
        out["names"][f"ns_join({ns!r},{name!r})"] = attempt(n.ns_join, ns, name)
    for caller in ("/node", "/wg/node1", "/"):
        out["names"][f"resolve_name({name!r},{caller!r})"] = attempt(
            n.resolve_name, name, caller, {"/wg/foo": "/x"}
        )
    out["names"][f"script_resolve_name('talker',{name!r})"] = attempt(n.script_resolve_name, "talker", name)
out["names"]["namespace(None)"] = attempt(n.namespace, None)
out["names"]["load_mappings"] = n.load_mappings(
    ["a:=b", "_p:=1", "__name:=x", "/c:=/d", "plain", "~e:=f", "bad-:=x"]
)
out["names"]["is_legal_remap"] = [n.is_legal_remap(a) for a in ("a:=b", "_p:=1", "__ns:=x", "a", "1:=2")]
out["names"]["make_caller_id"] = n.make_caller_id("talker")
out["names"]["get_ros_namespace"] = [
    n.get_ros_namespace(env={"ROS_NAMESPACE": "robot"}, argv=[]),
    n.get_ros_namespace(argv=["__ns:=/other"]),
]
out["names"]["anon"] = n.anonymous_name("x").startswith("x_") and n.is_legal_name(n.anonymous_name("x"))
out["names"]["consts"] = [n.SEP, n.GLOBALNS, n.PRIV_NAME, n.REMAP, n.ANYTYPE, n.MSG_EXT, n.SRV_EXT]
out["names"]["myargv"] = rosgraph.myargv(["prog", "a:=b", "x"])
out["names"]["get_master_uri"] = [
    rosgraph.get_master_uri(env={}, argv=[]),
    rosgraph.get_master_uri(env={"ROS_MASTER_URI": "http://h:1/"}, argv=["__master:=http://o:2/"]),
    attempt(rosgraph.get_master_uri, {}, ["__master:="]),
]

m = rosgraph.Master("/w1peer")
out["master"]["caller_id"] = [
    m.caller_id,
    rosgraph.Master("rel").caller_id,
    m.master_uri == os.environ["ROS_MASTER_URI"],
]
out["master"]["online"] = [
    rosgraph.is_master_online(),
    m.is_online(),
    rosgraph.is_master_online("http://localhost:1/"),
]
out["master"]["uri"] = (
    m.getUri().rstrip("/").split(":")[-1] == os.environ["ROS_MASTER_URI"].rstrip("/").split(":")[-1]
)
out["master"]["pid"] = isinstance(m.getPid(), int)
out["master"]["set"] = [m.setParam("/w1/a", 1), m.setParam("/w1/tree", {"x": 1.5, "y": {"z": "s"}})]
out["master"]["get"] = [m.getParam("/w1/a"), m.getParam("/w1/tree"), m.getParam("/w1")]
out["master"]["has"] = [m.hasParam("/w1/a"), m.hasParam("/w1/none")]
out["master"]["names"] = sorted(p for p in m.getParamNames() if p.startswith("/w1"))
out["master"]["search"] = [attempt(m.searchParam, "a"), attempt(rosgraph.Master("/w1/node").searchParam, "a")]
out["master"]["get_missing"] = attempt(m.getParam, "/w1/none")
out["master"]["delete"] = [attempt(m.deleteParam, "/w1/a"), attempt(m.deleteParam, "/w1/a")]
out["master"]["lookup_node_missing"] = attempt(m.lookupNode, "/no_such_node")
out["master"]["lookup_service_missing"] = attempt(m.lookupService, "/no_such_service")
api = "http://localhost:1234/"
out["master"]["register"] = [
    m.registerPublisher("/w1/chatter", "std_msgs/String", api),
    m.registerSubscriber("/w1/chatter", "std_msgs/String", api),
    m.registerService("/w1/srv", "rosrpc://localhost:1235", api),
]
out["master"]["lookup_node"] = m.lookupNode("/w1peer")
out["master"]["lookup_service"] = m.lookupService("/w1/srv")
pubs, subs, srvs = m.getSystemState()
out["master"]["state"] = [[e for e in part if e[0].startswith("/w1")] for part in (pubs, subs, srvs)]
out["master"]["published"] = [t for t in m.getPublishedTopics("") if t[0].startswith("/w1")]
out["master"]["published_sub"] = [t for t in m.getPublishedTopics("/w1") if t[0].startswith("/w1")]
out["master"]["types"] = [t for t in m.getTopicTypes() if t[0].startswith("/w1")]
out["master"]["handle"] = m.handle.getParam("/w1peer", "/w1/tree")
out["master"]["unregister"] = [
    m.unregisterPublisher("/w1/chatter", api),
    m.unregisterSubscriber("/w1/chatter", api),
    m.unregisterService("/w1/srv", "rosrpc://localhost:1235"),
]
out["master"]["errors"] = [
    issubclass(rosgraph.MasterError, rosgraph.MasterException),
    issubclass(rosgraph.MasterFailure, rosgraph.MasterException),
    rosgraph.masterapi.Error is rosgraph.MasterError,
]
dead = rosgraph.Master("/w1peer", master_uri="http://localhost:1/")
out["master"]["dead"] = attempt(dead.getPid)[:2]
try:
    dead.getParam("/x")
except OSError as exc:  # socket.error, as scripts catch it
    out["master"]["dead_socket_error"] = type(exc).__name__

out["network"]["parse"] = [
    attempt(net.parse_http_host_and_port, u) for u in ("http://foo:1234/", "http://foo/", "", "foo:12")
]
hdr = net.encode_ros_handshake_header({"topic": "/a", "md5sum": "*", "callerid": "/n"})
out["network"]["encode"] = hdr.hex()
out["network"]["decode"] = net.decode_ros_handshake_header(hdr + b"extra")
out["network"]["decode_bad"] = [
    attempt(net.decode_ros_handshake_header, hdr[:-3]),
    attempt(net.decode_ros_handshake_header, b"\x04\x00\x00\x00\x00\x00\x00\x00"),
    attempt(net.decode_ros_handshake_header, b"\x07\x00\x00\x00\x03\x00\x00\x00abc"),
]
out["network"]["bind"] = [net.get_bind_address(a) for a in ("localhost", "127.0.1.1", "10.0.0.1", "::1")]
out["network"]["xmlrpc_uri"] = net.create_local_xmlrpc_uri(1234)
out["network"]["host"] = [net.get_host_name(), net.get_local_address(), net.use_ipv6()]
out["network"]["local"] = [net.is_local_address("localhost"), net.is_local_address("no.such.host.invalid")]
out["network"]["addrs"] = sorted(net.get_local_addresses())
print(json.dumps(out, sort_keys=True))
