"""``rosrun map_server map_server map.yaml`` and ``rosrun map_server map_saver -f name``.

map_server publishes the map on ``map`` and its ``map_metadata`` (both latched) and answers
``static_map`` (nav_msgs/GetMap); ``~frame_id`` (default ``map``) names the map's frame. A map that
does not load is one error line naming the file and the field; unlike ROS 1 the node keeps running
(it has nothing to publish until restarted with a good file).

map_saver waits for one OccupancyGrid on ``map`` and writes ``<name>.pgm`` and ``<name>.yaml``
(``-f name``, default ``map``; ``--occ``/``--free`` thresholds in percent, 65 and 25), then exits.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path

from ninjemys.maps.mapfile import MapFileError, load_map, save_map
from ninjemys.nav.rosglue import grid_from_msg, grid_to_msg, param, run_core_node
from ninjemys.node.node import Node

USAGE = "USAGE: map_server <map.yaml>\n  map.yaml: map description file"
SAVER_USAGE = "Usage: \n  map_saver -h\n  map_saver [--occ <threshold_occupied>] [--free <threshold_free>] [-f <mapname>] [ROS remapping args]"


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    files = [a for a in args if ":=" not in a]
    if len(files) != 1:
        print(USAGE, file=sys.stderr)
        return 1
    from nav_msgs.msg import MapMetaData, OccupancyGrid
    from nav_msgs.srv import GetMap, GetMapResponse

    path = files[0]

    def serve(node: Node) -> None:
        frame_id = param(node, "frame_id", "map")
        try:
            grid = load_map(path)
        except MapFileError as exc:
            node.log.error("map_server: %s", exc)  # and keep running, with nothing to offer
            return
        msg = grid_to_msg(grid, frame_id, node.get_time(), cls=OccupancyGrid)
        node.log.info("Read a %d X %d map @ %.3f m/cell", grid.width, grid.height, grid.resolution)
        meta_pub = node.publisher("map_metadata", MapMetaData, latch=True, queue_size=1)
        map_pub = node.publisher("map", OccupancyGrid, latch=True, queue_size=1)
        meta_pub.publish(msg.info)
        map_pub.publish(msg)

        def on_static_map(_req: object) -> object:
            node.log.info("Sending map")
            return GetMapResponse(map=msg)

        node.service("static_map", GetMap, on_static_map)

    return run_core_node("map_server", args, serve)


def saver_main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    plain = [a for a in args if ":=" not in a]
    name, occ, free = "map", 65, 25
    i = 0
    while i < len(plain):
        a = plain[i]
        if a == "-h" or a == "--help":
            print(SAVER_USAGE)
            return 0
        if a in ("-f", "--occ", "--free") and i + 1 < len(plain):
            value = plain[i + 1]
            if a == "-f":
                name = value
            else:
                try:
                    number = int(value)
                except ValueError:
                    print(f"map_saver: {a} needs an integer percentage, got {value!r}", file=sys.stderr)
                    return 1
                occ, free = (number, free) if a == "--occ" else (occ, number)
            i += 2
            continue
        print(SAVER_USAGE, file=sys.stderr)
        return 1
    if not (0 <= free < occ <= 100):
        print(
            "map_saver: threshold_free must be smaller than threshold_occupied, both 0..100", file=sys.stderr
        )
        return 1
    from nav_msgs.msg import OccupancyGrid

    done = threading.Event()

    def wait_for_map(node: Node) -> None:
        def on_map(msg: object) -> None:
            if done.is_set():
                return
            grid = grid_from_msg(msg)
            node.log.info("Received a %d X %d map @ %.3f m/pix", grid.width, grid.height, grid.resolution)
            base = Path(name)
            node.log.info("Writing map occupancy data to %s.pgm", base)
            try:
                save_map(grid, base, occ, free)
            except OSError as exc:
                node.log.error("map_saver: cannot write %s: %s", base, exc.strerror or exc)
            else:
                node.log.info("Writing map occupancy data to %s.yaml", base)
                node.log.info("Done\n")
            done.set()
            # not from this subscription's own worker thread, which the shutdown joins
            threading.Thread(target=node.shutdown, args=("map saved",), name="shutdown", daemon=True).start()

        node.log.info("Waiting for the map")
        node.subscriber("map", OccupancyGrid, on_map)

    code = run_core_node("map_saver", args, wait_for_map)
    return code or (0 if done.is_set() else 1)
