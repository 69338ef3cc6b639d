"""The parser follows genmsg's rules exactly; malformed input names file and line."""

from __future__ import annotations

from pathlib import Path

import pytest

from ninjemys.errors import DefinitionError
from ninjemys.idl.parser import (
    ACTION_AUTOGEN,
    action_message_texts,
    parse_action,
    parse_file,
    parse_message,
    parse_service,
)
from ninjemys.idl.spec import FieldType


def test_fields_arrays_and_type_resolution() -> None:
    spec = parse_message(
        "Header header\nPoint p\nstd_msgs/String s\nuint8[] data\nfloat64[9] cov\nPoint[] ps\nHeader[] hs\n",
        "geometry_msgs/Thing",
    )
    types = {f.name: f.type for f in spec.fields}
    assert types["header"] == FieldType("std_msgs/Header")
    assert types["p"] == FieldType("geometry_msgs/Point")
    assert types["s"] == FieldType("std_msgs/String")
    assert types["data"] == FieldType("uint8", True, None)
    assert types["cov"] == FieldType("float64", True, 9)
    assert types["ps"] == FieldType("geometry_msgs/Point", True, None)
    # genmsg only maps the exact word "Header": an array of it resolves in the package
    assert types["hs"] == FieldType("geometry_msgs/Header", True, None)
    assert spec.has_header
    assert spec.dependencies == (
        "std_msgs/Header",
        "geometry_msgs/Point",
        "std_msgs/String",
        "geometry_msgs/Header",
    )


def test_byte_and_char_keep_their_spelling() -> None:
    spec = parse_message("byte a\nchar b\nbyte[] c\n", "p/T")
    assert [str(f.type) for f in spec.fields] == ["byte", "char", "byte[]"]


def test_constants_follow_genmsg() -> None:
    spec = parse_message(
        "int8 A = -5  # comment\n"
        "string S=hello # not a comment = still text \n"
        "string E =  spaced  \n"
        "float64 F=1.5\n"
        "bool B=True\n"
        "uint64 BIG=18446744073709551615\n",
        "p/T",
    )
    consts = {c.name: c for c in spec.constants}
    assert consts["A"].value == -5 and consts["A"].value_text == "-5"
    assert consts["S"].value == "hello # not a comment = still text"
    assert consts["S"].value_text == "hello # not a comment = still text"
    assert consts["E"].value == "spaced"
    assert consts["F"].value == 1.5
    assert consts["B"].value is True
    assert consts["BIG"].value == 2**64 - 1
    assert spec.fields == ()


def test_comments_and_blank_lines_are_ignored_but_text_is_kept() -> None:
    text = "# top\n\n  int32 x   # the x\n\t\n"
    spec = parse_message(text, "p/T")
    assert [f.name for f in spec.fields] == ["x"]
    assert spec.text == text


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("int32 x\nint32\n", 2, "expected 'TYPE NAME'"),
        ("int32 x y\n", 1, "expected 'TYPE NAME'"),
        ("int32 9x\n", 1, "legal message field name"),
        ("in-t32 x\n", 1, "legal message field type"),
        ("int32[x] a\n", 1, "invalid array dimension"),
        ("int32[1][2] a\n", 1, "1-D arrays"),
        ("\n\ntime T=3\n", 3, "not a legal constant type"),
        ("uint8 X=300\n", 1, "out of bounds"),
        ("int32 X=abc\n", 1, "invalid constant value"),
        ("Point P=1\n", 1, "not a legal constant type"),
        ("int32 x\nfloat64 x\n", 2, "duplicate"),
    ],
)
def test_malformed_definitions_name_file_and_line(text: str, line: int, reason: str, tmp_path: Path) -> None:
    path = tmp_path / "pkg" / "msg" / "Bad.msg"
    path.parent.mkdir(parents=True)
    path.write_text(text)
    with pytest.raises(DefinitionError) as info:
        parse_file(path, "pkg")
    assert info.value.path == str(path)
    assert info.value.line == line
    assert reason in str(info.value)
    assert str(info.value).startswith(f"{path}:{line}: ")


def test_service_halves_are_comment_stripped_like_genmsg() -> None:
    srv = parse_service("# c\nint64 a  # first\nstring op\n---\nint64 result\nInner detail\n", "p/Compute")
    assert srv.request.full_name == "p/ComputeRequest"
    assert srv.response.full_name == "p/ComputeResponse"
    assert srv.request.text == "\nint64 a\nstring op\n"
    assert srv.response.text == "int64 result\nInner detail\n\n"  # the last empty line counts
    assert srv.response.fields[1].type == FieldType("p/Inner")


def test_service_without_separator_has_empty_response() -> None:
    srv = parse_service("int32 a\n", "p/OneWay")
    assert [f.name for f in srv.request.fields] == ["a"]
    assert srv.response.fields == ()


def test_action_expands_to_seven_messages_like_genaction() -> None:
    texts = action_message_texts("int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n", "p/Fib")
    assert list(texts) == [
        "FibAction",
        "FibActionGoal",
        "FibActionResult",
        "FibActionFeedback",
        "FibGoal",
        "FibResult",
        "FibFeedback",
    ]
    assert texts["FibGoal"] == ACTION_AUTOGEN + "int32 order\n"
    assert (
        texts["FibActionGoal"]
        == ACTION_AUTOGEN + "\nHeader header\nactionlib_msgs/GoalID goal_id\nFibGoal goal\n"
    )
    action = parse_action("int32 order\n---\nint32[] sequence\n---\nint32[] sequence\n", "p/Fib")
    assert [s.full_name for s in action.generated][0] == "p/FibAction"
    assert action.generated[1].has_header


def test_action_needs_two_separators() -> None:
    with pytest.raises(DefinitionError, match="two '---' lines"):
        parse_action("int32 a\n---\nint32 b\n", "p/Broken", "/x/Broken.action")
