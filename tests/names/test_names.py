from ninjemys import names


def test_resolution_matches_ros1_rules():
    assert names.resolve_name("bar", "/wg/node1") == "/wg/bar"
    assert names.resolve_name("/bar", "/wg/node1") == "/bar"
    assert names.resolve_name("~bar", "/wg/node1") == "/wg/node1/bar"
    assert names.resolve_name("a//b/", "/node") == "/a/b"
    assert names.resolve_name("", "/wg/node1") == "/wg/"


def test_remapping_is_resolved_before_matching():
    remaps = names.resolve_remappings(
        names.load_mappings(["chatter:=/news", "__name:=x", "_rate:=5"]), "/ns/talker"
    )
    assert remaps == {"/ns/chatter": "/news"}
    assert names.resolve_name("chatter", "/ns/talker", remaps) == "/news"
    assert names.private_param_args(["_rate:=5", "__ns:=/a", "foo:=bar"]) == {"rate": "5"}
    assert names.strip_remap_args(["prog", "a:=b", "x"]) == ["prog", "x"]


def test_namespaces_and_legality():
    assert names.namespace("/a/b") == "/a/"
    assert names.namespace("/a") == "/"
    assert names.get_ros_namespace({"ROS_NAMESPACE": "robot"}, ["__ns:=/other"]) == "/other/"
    assert names.is_legal_name("/a/b_c") and names.is_legal_name("~p") and not names.is_legal_name("1abc")
    assert not names.is_legal_name("a b")
