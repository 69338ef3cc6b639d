"""``cv_bridge.boost.cv_bridge_boost`` (cvtColorForDisplay, getCvType, cvtColor2) against Debian's
compiled module: the same images give the same pixels, or the same exception class and text."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cv_bridge import cvtColorForDisplay, getCvType
from ninjemys.testing import ROS1_PYTHON, ros1_env

PEER = str(Path(__file__).with_name("cvb_display_peer.py"))


def run(python: str, env: dict[str, str] | None) -> list:
    done = subprocess.run([python, PEER], capture_output=True, text=True, env=env, timeout=60, cwd="/")
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


@pytest.mark.ros1
def test_display_and_types_match_ros1() -> None:
    ours = run(sys.executable, None)
    theirs = run(ROS1_PYTHON, ros1_env("http://localhost:11311"))
    assert len(ours) == len(theirs)
    for i, (a, b) in enumerate(zip(ours, theirs, strict=True)):
        assert a == b, i


def test_depth_scaled_to_gray_and_labels_colored() -> None:
    depth = np.array([[1.0, 3.0]], np.float32)
    shown = cvtColorForDisplay(depth, "32FC1", "bgr8", True)
    assert (
        shown.shape == (1, 2, 3) and shown[0, 0].tolist() == [0, 0, 0] and shown[0, 1].tolist() == [255] * 3
    )
    labels = cvtColorForDisplay(np.array([[-1, 7]], np.int32), "32SC1", "")
    assert labels[0, 0].tolist() == [0, 0, 0] and labels[0, 1].tolist() == [0, 0, 0]  # label 7 is black
    assert getCvType("rgb8") == 16
    with pytest.raises(RuntimeError, match=r"Unrecognized image encoding \[nope\]"):
        getCvType("nope")
