"""Run under Debian's /usr/bin/python3: genpy's view of message types given as full definition texts.

Reads JSON ``[{"type": ..., "full_text": ..., "data": hex}, ...]`` on stdin and prints, per item, the
md5sum genpy computes from the text, genpy's re-serialization of ``data`` (hex) and ``str()`` of the
decoded message (the YAML form rostopic echo prints). Used as an independent oracle for fixture types
that no ROS 1 package ships.
"""

from __future__ import annotations

import io
import json
import sys

from genpy.dynamic import generate_dynamic


def main() -> None:
    out = []
    for item in json.load(sys.stdin):
        classes = generate_dynamic(item["type"], item["full_text"])
        cls = classes[item["type"]]
        msg = cls().deserialize(bytes.fromhex(item["data"]))
        buff = io.BytesIO()
        msg.serialize(buff)
        out.append({"md5": cls._md5sum, "data": buff.getvalue().hex(), "str": str(msg)})
    json.dump(out, sys.stdout)


if __name__ == "__main__":
    main()
