"""A ninjemys talker in its own process (for SIGKILL and restart tests): publishes "tag i" at 50 Hz."""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from node_msgs import String  # noqa: E402

from ninjemys.node import Node  # noqa: E402


def main() -> None:
    master_uri, name, topic, tag = sys.argv[1:5]
    node = Node(name, master_uri=master_uri)
    pub = node.publisher(topic, String)
    print("ready", flush=True)
    i = 0
    while not node.is_shutdown:
        pub.publish(String(f"{tag} {i}"))
        i += 1
        time.sleep(0.02)


if __name__ == "__main__":
    main()
