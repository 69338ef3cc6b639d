"""Fields and constants named like Python keywords get genpy's trailing underscore (issue 21: the
"Mastering ROS" book's ``demo_srv.srv`` is ``string in`` / ``string out``; loading it raised).

genpy appends ``_`` to a field or constant named like a keyword or ``self`` (``req.in_``,
``Kw.class_``); the wire format, the definition text and the md5sum keep the name as written. The
same script runs through Debian's genpy and ours."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from ninjemys import testing

SCRIPT = r"""
import json, genpy.dynamic
classes = genpy.dynamic.generate_dynamic(
    "kw_pkg/Kw", "int32 class=1\nint32 from\nstring in\nbool self\nKwInner inner\n"
    "================================================================================\n"
    "MSG: kw_pkg/KwInner\nfloat64 lambda\n")
Kw = classes["kw_pkg/Kw"]
msg = Kw(from_=3, in_="x", self_=True)
msg.inner.lambda_ = 2.5
import io
buf = io.BytesIO()
msg.serialize(buf)
back = Kw()
back.deserialize(buf.getvalue())
print(json.dumps({
    "slots": list(Kw.__slots__), "md5": Kw._md5sum, "class_": Kw.class_,
    "inner_slots": list(type(msg.inner).__slots__), "bytes": buf.getvalue().hex(),
    "back": [back.from_, back.in_, back.self_, back.inner.lambda_], "text": str(back),
}))
"""


def _run(python: str) -> dict[str, object]:
    env = testing.ros1_env("http://localhost:1") if python == testing.ROS1_PYTHON else None
    out = subprocess.run(
        [python, "-c", SCRIPT], capture_output=True, text=True, timeout=60, check=False, env=env
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_keyword_names_get_an_underscore() -> None:
    ours = _run(sys.executable)
    assert ours["slots"] == ["from_", "in_", "self_", "inner"]
    assert ours["inner_slots"] == ["lambda_"] and ours["class_"] == 1
    assert ours["back"] == [3, "x", True, 2.5]


@pytest.mark.ros1
@pytest.mark.skipif(not testing.have_ros1(), reason="Debian's ROS 1 is not installed")
def test_same_names_bytes_and_md5_as_genpy() -> None:
    assert _run(sys.executable) == _run(testing.ROS1_PYTHON)
