"""``rosrun image_transport republish in_transport in:=<in_base> [out_transport] out:=<out_base>``.

ROS 1's argument forms: ``in_transport`` is ``raw`` or ``compressed`` (subscribing to ``<in>`` or
``<in>/compressed``); ``out_transport`` ``raw`` publishes ``<out>``, ``compressed`` publishes
``<out>/compressed``, and no ``out_transport`` publishes every transport (``<out>`` and
``<out>/compressed``), as image_transport's publisher does. Work is done only for subscribed outputs.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

from ninjemys.node.run import run_node

TRANSPORTS = ("raw", "compressed")
USAGE = "Usage: republish in_transport in:=<in_base_topic> [out_transport] out:=<out_base_topic>"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    plain = [a for a in argv if ":=" not in a]  # remappings and _params are the node's
    if not plain or len(plain) > 2:
        print(USAGE, file=sys.stderr)
        return 1
    in_transport = plain[0]
    out_transport = plain[1] if len(plain) > 1 else None
    for t in (in_transport, out_transport):
        if t is not None and t not in TRANSPORTS:
            print(
                f'republish: no image transport plugin "{t}" (ninjemys has: {", ".join(TRANSPORTS)})',
                file=sys.stderr,
            )
            return 1

    def build(node: Any) -> None:
        from ninjemys.idl.loader import get_message_class
        from ninjemys.image_transport.compressed import CompressedPublisher, decode

        Image = get_message_class("sensor_msgs/Image")
        raw_pub = None
        comp_pub = None
        if out_transport in (None, "raw"):
            raw_pub = node.publisher(node.resolve_name("out"), Image, queue_size=1)
        if out_transport in (None, "compressed"):
            comp_pub = CompressedPublisher(node, "out", queue_size=1)

        def on_image(img: Any) -> None:
            if raw_pub is not None and raw_pub.get_num_connections():
                raw_pub.publish(img)
            if comp_pub is not None:
                comp_pub.publish(img)

        if in_transport == "raw":
            node.subscriber(node.resolve_name("in"), Image, on_image, queue_size=1)
        else:

            def on_compressed(cmsg: Any) -> None:
                if raw_pub is not None and raw_pub.get_num_connections():
                    raw_pub.publish(decode(cmsg))
                if comp_pub is not None:
                    comp_pub.publish_compressed(cmsg)  # compressed -> compressed: the bytes as they came

            node.subscriber(
                node.resolve_name("in") + "/compressed",
                get_message_class("sensor_msgs/CompressedImage"),
                on_compressed,
                queue_size=1,
            )

    # anonymous, as ROS 1's (init_options::AnonymousName): several republishers run side by side
    name = f"image_republisher_{os.getpid()}_{int(time.time() * 1000) % 10**9}"
    return run_node(name, argv, build)
