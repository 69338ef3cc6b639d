"""The built-in YAML emitter prints exactly what ROS 1's rosparam prints through PyYAML.

The oracle is PyYAML set up as ROS 1's rosparam sets it up: ``yaml.dump(value)`` with the default
dumper, on which rosparam registers its ``deg(...)``/``rad(...)`` implicit resolvers.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys

import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from ninjemys.paramyaml import dump_yaml
from ninjemys.paramyaml_emit import dump, implicit_type


class RosparamDumper(yaml.Dumper):
    """yaml.Dumper after ``import rosparam`` (which adds the angle resolvers to the global dumper)."""


RosparamDumper.add_implicit_resolver("!degrees", re.compile(r"^deg\([^\)]*\)$"), list("deg("))
RosparamDumper.add_implicit_resolver("!radians", re.compile(r"^rad\([^\)]*\)$"), list("rad("))


def ros1_dump(value: object) -> str:
    return yaml.dump(value, Dumper=RosparamDumper)


#: strings that need care: quoting triggers, YAML 1.1 look-alikes, folding, escapes, breaks
TRICKY = [
    "",
    " ",
    " lead",
    "trail ",
    "a: b",
    "a:b",
    "key:",
    "a #b",
    "a#b",
    "#x",
    "- x",
    "-x",
    "-",
    "? x",
    "?x",
    ":x",
    "---",
    "...",
    "--- x",
    "yes",
    "No",
    "ON",
    "off",
    "y",
    "n",
    "true",
    "False",
    "null",
    "Null",
    "~",
    "=",
    "<<",
    "!",
    "&a",
    "*a",
    "%x",
    "@x",
    "`x",
    "'q'",
    '"dq"',
    "it's",
    "a\\b",
    "12",
    "-12",
    "+12",
    "012",
    "0o12",
    "0x1F",
    "0b101",
    "1_000",
    "1:20",
    "190:20:30.15",
    "1.5",
    ".5",
    "1e5",
    "1.0e+5",
    ".inf",
    "-.Inf",
    ".NaN",
    "2001-12-14",
    "2001-12-14t21:59:43.10-05:00",
    "2001-12-14 21:59:43.10 -5",
    "deg(90)",
    "rad(pi/2)",
    "deg(",
    "héllo wörld",
    "snow \u2603",
    "emoji \U0001f600",
    "nbsp\xa0x",
    "bom\ufeff",
    "nel\x85x",
    "ls\u2028x",
    "tab\tx",
    "nul\x00x",
    "bell\x07",
    "esc\x1b",
    "line1\nline2",
    "line1\n",
    "\nline2",
    "a\n\nb",
    "a \nb",
    "a\n b",
    "a\r\nb",
    "x" * 100,
    " ".join(["word"] * 40),
    " ".join(["w"] * 100),
    "a" * 79 + " b",
    "a" * 80 + " b c",
    "'" + " ".join(["quoted"] * 20),
    "é" + " ".join(["esc"] * 40),
    "é" * 90,
    "\u2603" * 30 + " " * 3 + "x" * 60,
    "<robot name='r'>\n  <link name='base_link'>\n    <visual><geometry><box size='1 1 1'/></geometry>"
    "</visual>\n  </link>\n</robot>\n",
]

scalars = st.one_of(
    st.text(
        alphabet=st.sampled_from(list(" ab:#'\"-?\n\t\\é\u2603.~!&*0123456789xyYnN\x85\u2028\xa0")),
        max_size=24,
    ),
    st.text(max_size=16),
    st.sampled_from(TRICKY),
    st.lists(st.sampled_from(["a", "bb", "x" * 12, "é", "'", ":", "#", "", "\n", "-"]), max_size=40).map(
        " ".join
    ),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.none(),
)
keys = st.one_of(
    st.text(min_size=0, max_size=12), st.sampled_from(TRICKY), st.from_regex(r"[a-z_][a-z0-9_]{0,15}")
)
trees = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=5), st.dictionaries(keys, inner, max_size=5)),
    max_leaves=30,
)
#: what a parameter server holds: name-like keys, so the emitter never needs to hand over to PyYAML
param_keys = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,20}", fullmatch=True)
param_trees = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=5), st.dictionaries(param_keys, inner, max_size=5)),
    max_leaves=30,
)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees)
@example({"": 1, "a\nb": 2, "k" * 130: 3})
@example([1.0e17, -0.0, 1e-10, 123456789.123, math.pi, float("inf"), float("-inf"), float("nan")])
def test_same_text_as_pyyaml_or_hands_over(value):
    ours = dump(value)
    if ours is not None:
        assert ours == ros1_dump(value)
    assert dump_yaml(value) == ros1_dump(value)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(param_trees)
def test_parameter_trees_never_need_pyyaml(value):
    ours = dump(value)
    assert ours is not None
    assert ours == ros1_dump(value)


def test_every_tricky_string_as_value_key_and_item():
    for text in TRICKY:
        for value in (text, {"k": text}, [text, [text]], {"outer": {"inner": [text, {"deep": text}]}}):
            assert dump_yaml(value) == ros1_dump(value), value
        if text and "\n" not in text and len(text) < 128 and not any(c in text for c in "\x85\u2028\u2029"):
            value = {text: [1, {text: text}]}
            assert dump(value) == ros1_dump(value), value


def test_implicit_types_match_pyyaml_resolution():
    for text in TRICKY:
        kind = implicit_type(text)
        resolved = RosparamDumper.resolve(RosparamDumper, yaml.ScalarNode, text, (True, False))
        assert (kind == "str") == (resolved == "tag:yaml.org,2002:str"), text


@settings(max_examples=500, deadline=None)
@given(
    st.one_of(
        st.text(
            alphabet=st.sampled_from(list("0123456789_.:+-eExXbBaAfFinINTtZ \tyesnoul~<=!&*(d)r")),
            max_size=14,
        ),
        st.text(max_size=8),
    )
)
def test_implicit_types_match_pyyaml_on_random_text(text):
    resolved = RosparamDumper.resolve(RosparamDumper, yaml.ScalarNode, text, (True, False))
    assert (implicit_type(text) == "str") == (resolved == "tag:yaml.org,2002:str")


def test_hands_over_what_it_cannot_print():
    shared = [1, 2]
    for value in ({"a": shared, "b": shared}, b"\x00\x01binary", {1: "int key"}, (1, 2), {"": 1}):
        assert dump(value) is None
    assert dump_yaml(b"\x00\x01") == "!!binary |\n  AAE=\n"
    assert dump_yaml({"a": shared, "b": shared}) == ros1_dump({"a": shared, "b": shared})


def test_printing_does_not_import_pyyaml():
    """The point of the emitter: `rosparam get` start-up without PyYAML (nor argparse)."""
    code = (
        "import sys\n"
        "import ninjemys.tools.rosparam\n"
        "from ninjemys.paramyaml import dump_yaml\n"
        "text = dump_yaml({'robot': {'name': 'r2', 'gains': [1.5, -2, True], 'note': 'a: b'}})\n"
        "assert text.startswith('robot:'), text\n"
        "print(sorted(m for m in ('yaml', 'argparse', 'optparse', 'pathlib') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "[]"
