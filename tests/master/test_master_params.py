"""The parameter tree and paramUpdate computation (pure data, ROS 1 semantics)."""

from __future__ import annotations

import pytest

from ninjemys.master.params import ParamTree, compute_updates, subscription_key


def test_dict_replaces_subtree_and_namespaces_are_dicts() -> None:
    tree = ParamTree()
    tree.set("/a/x", 1)
    tree.set("/a/y", 2)
    tree.set("/a", {"z": 3})
    assert tree.get("/a") == {"z": 3}
    assert not tree.has("/a/x")
    tree.set("/a/z/deep", 4)  # a leaf becomes a namespace
    assert tree.get("/") == {"a": {"z": {"deep": 4}}}


def test_missing_and_root_rules() -> None:
    tree = ParamTree()
    with pytest.raises(KeyError):
        tree.get("/nope")
    with pytest.raises(KeyError):
        tree.delete("/")
    with pytest.raises(TypeError):
        tree.set("/", 5)
    tree.set("/", {"r": 1})
    assert tree.names() == ["/r"]


def test_names_are_leaves_in_order() -> None:
    tree = ParamTree()
    tree.set("/b", 1)
    tree.set("/a/c", 2)
    tree.set("/a/d/e", 3)
    tree.set("/z", {})
    assert tree.names() == ["/b", "/a/c", "/a/d/e"]


def test_search_walks_up_from_the_callers_name() -> None:
    tree = ParamTree()
    tree.set("/robot_description", "top")
    tree.set("/pr2/robot_description", "pr2")
    assert tree.search("/pr2/foo", "robot_description") == "/pr2/robot_description"
    assert tree.search("/pr2/foo", "robot_description/arm") == "/pr2/robot_description/arm"
    assert tree.search("/other/node", "robot_description") == "/robot_description"
    assert tree.search("/other/node", "missing") is None
    assert tree.search("/x", "/robot_description") == "/robot_description"
    tree.set("/n/mine", 1)
    assert tree.search("/n", "mine") == "/n/mine"  # the caller's own private namespace first
    with pytest.raises(ValueError):
        tree.search("/x", "~p")


def test_subscription_keys_have_trailing_slash() -> None:
    assert subscription_key("/a//b") == "/a/b/"
    assert subscription_key("/") == "/"


def test_updates_to_ancestor_subscribers_skip_the_caller() -> None:
    subs = {"/a/": {("/n1", "http://n1/"): None, ("/setter", "http://s/"): None}}
    updates = compute_updates(subs, "/a/b", 5, ignore_caller="/setter")
    assert updates == [([("/n1", "http://n1/")], "/a/b/", 5)]


def test_subtree_set_notifies_sub_keys_with_value_or_empty_dict() -> None:
    subs = {"/t/keep/": [("/n", "http://n/")], "/t/gone/": [("/m", "http://m/")], "/other/": [("/o", "u")]}
    updates = compute_updates(subs, "/t", {"keep": 1, "new": 2})
    assert sorted(updates) == sorted(
        [([("/n", "http://n/")], "/t/keep/", 1), ([("/m", "http://m/")], "/t/gone/", {})]
    )


def test_delete_sends_empty_dict() -> None:
    subs = {"/d/": [("/n", "http://n/")]}
    assert compute_updates(subs, "/d", {}) == [([("/n", "http://n/")], "/d/", {})]
