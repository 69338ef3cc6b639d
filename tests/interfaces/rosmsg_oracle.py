"""Run under Debian's /usr/bin/python3: print real rosmsg's ``show`` text of many types as one JSON object.

``rosmsg show`` starts a Python interpreter per call; asking its library (the functions the command
itself prints from) for every type in one process keeps the comparison test to a second.
Usage: rosmsg_oracle.py msg|srv RAW(0/1) TYPE...
"""

from __future__ import annotations

import json
import sys

import rosmsg

import rospkg


def main() -> None:
    mode, raw, types = sys.argv[1], sys.argv[2] == "1", sys.argv[3:]
    rospack = rospkg.RosPack()
    ext = rosmsg.MODE_MSG if mode == "msg" else rosmsg.MODE_SRV
    out = {}
    for type_name in types:
        try:
            out[type_name] = (
                rosmsg.get_msg_text(type_name, raw=raw, rospack=rospack)
                if ext == rosmsg.MODE_MSG
                else rosmsg.get_srv_text(type_name, raw=raw, rospack=rospack)
            )
        except Exception as exc:  # report, do not stop the batch
            out[type_name] = f"ERROR {type(exc).__name__}: {exc}"
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
