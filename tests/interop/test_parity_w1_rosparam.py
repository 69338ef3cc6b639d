"""rosparam's Python API against Debian's: load_file/load_str (``_ns`` documents, angles, binary),
upload_params, get/set/set_raw/delete/list/dump, and the errors of bad input (missing file, bad YAML
as a yaml.YAMLError, non-string keys, a non-dict for ``/``).

Not compared: an integer past sys.maxsize, where ROS 1's set_param_raw fails with a NameError of its
own (``maxint``); ours raises the RosParamException it meant."""

from __future__ import annotations

import pytest
from test_parity_behaviour import compare

pytestmark = pytest.mark.ros1


def test_rosparam_api_matches_ros1() -> None:
    compare("parity_w1_rosparam_peer.py", with_master=True)
