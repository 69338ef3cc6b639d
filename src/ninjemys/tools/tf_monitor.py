"""``rosrun tf tf_monitor [framea frameb]``: delays and rates of everything on ``/tf`` and ``/tf_static``.

Every ~0.2 s it prints ROS 1's report: per frame, who publishes it and the average and maximum delay
between a transform's stamp and its arrival; per broadcaster, its rate and delays; with two frames,
also the chain between them and the net delay of looking it up. Text and layout are tf_monitor's
(including "All Broadcasters:" on stderr).
"""

from __future__ import annotations

import sys
import threading
from collections import deque
from typing import TYPE_CHECKING

from ninjemys.tools.cli import entry, wait_for_master_like_roscpp

if TYPE_CHECKING:
    from ninjemys.node import Node


class Monitor:
    """The bookkeeping of tf_monitor, fed by ``record`` (pure: tests drive it directly)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.frame_authority: dict[str, str] = {}
        self.delays: dict[str, deque[float]] = {}
        self.authority_delays: dict[str, deque[float]] = {}
        self.authority_times: dict[str, deque[float]] = {}

    def record(self, frames: list[tuple[str, float | None]], authority: str, now: float) -> None:
        """One message: ``(child_frame_id, stamp seconds or None for static)`` pairs from ``authority``."""
        with self.lock:
            total = 0.0
            for child, stamp in frames:
                self.frame_authority[child] = authority
                offset = 0.0 if stamp is None else now - stamp
                total += offset
                self.delays.setdefault(child, deque(maxlen=1000)).append(offset)
            self.authority_delays.setdefault(authority, deque(maxlen=1000)).append(
                total / max(1, len(frames))
            )
            self.authority_times.setdefault(authority, deque(maxlen=1000)).append(now)

    def report(self, chain: list[str] | None) -> tuple[str, str, str]:
        """(frames, the broadcasters' heading, broadcasters) of one report; tf_monitor prints the heading
        on stderr and the rest on stdout. ``chain`` limits the frames listed."""
        out = ["\nFrames:\n"]
        nodes: list[str] = []
        with self.lock:
            for frame in sorted(self.delays):
                if chain is not None and frame not in chain:
                    continue
                d = self.delays[frame]
                out.append(
                    f"Frame: {frame} published by {self.frame_authority[frame]} Average Delay: {sum(d) / len(d):g} "
                    f"Max Delay: {max(0.0, max(d)):g}\n"
                )
            err = "\nAll Broadcasters:\n"
            for who in sorted(self.authority_delays):
                d = self.authority_delays[who]
                times = self.authority_times[who]
                freq = len(times) / max(0.00000001, times[-1] - times[0])
                nodes.append(
                    f"Node: {who} {freq:g} Hz, Average Delay: {sum(d) / len(d):g} Max Delay: {max(0.0, max(d)):g}\n"
                )
        return "".join(out), err, "".join(nodes)


def main(argv: list[str] | None = None) -> int:
    from ninjemys.names import strip_remap_args
    from ninjemys.node.run import run_main

    argv = sys.argv[1:] if argv is None else argv
    args = strip_remap_args(["tf_monitor", *argv])[1:]
    return run_main("tf_monitor", argv, lambda node: monitor(node, args), anonymous=True)


def monitor(node: Node, args: list[str]) -> int:
    """tf_monitor's loop on a core node (a roscpp program in ROS 1: it waits for the master as roscpp does)."""
    from ninjemys.tf2.core import BufferCore
    from ninjemys.tf2.errors import TransformException
    from ninjemys.tf2.node import TransformListener
    from ninjemys.tf2.wire import decode_tf_message

    if len(args) not in (0, 2):
        node.log.info("TF_Monitor: usage: tf_monitor framea frameb")
        return 255
    if not wait_for_master_like_roscpp(node):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    buffer = BufferCore()
    TransformListener(node, buffer, now=node.get_time, report=node.log.warn)
    books = Monitor()

    def on_message(raw: object, static: bool) -> None:
        who = raw.connection_header.get("callerid", "")  # type: ignore[attr-defined]
        items = decode_tf_message(raw.data)  # type: ignore[attr-defined]
        frames = [(it[1], None if static else it[2] / 1e9) for it in items]
        books.record(frames, who + "(static)" if static else who, node.get_time())

    chain: list[str] | None = None
    framea = frameb = ""
    if args:
        framea, frameb = args[0].lstrip("/"), args[1].lstrip("/")
        sys.stdout.write(f"Waiting for transform chain to become available between {framea} and {frameb} ")
        sys.stdout.flush()
        while (
            not node.is_shutdown
            and not buffer.wait_for_transform(
                lambda: buffer.can_transform(framea, frameb, 0), 1.0, node.get_time, lambda: node.is_shutdown
            )[0]
        ):
            sys.stdout.write(".")
            sys.stdout.flush()
        sys.stdout.write("\n")
        try:
            chain = buffer.chain(frameb, 0, framea, 0, frameb)
        except TransformException as ex:
            node.log.warn(f"Transform Exception {ex}")
            return 0
    node.subscriber("/tf", None, on_message, callback_args=False, raw=True)
    node.subscriber("/tf_static", None, on_message, callback_args=True, raw=True)
    max_diff = avg_diff = 0.0
    counter = 0
    while not node.is_shutdown:
        counter += 1
        if chain is not None:
            try:
                stamp, _ = buffer.lookup(framea, frameb, 0)
                diff = node.get_time() - stamp / 1e9
                avg_diff = 0.01 * diff + 0.99 * avg_diff
                max_diff = max(max_diff, diff)
            except TransformException:
                pass
        node.sleep(0.01)  # raises ShutdownError at Ctrl-C: run_main ends quietly
        if counter > 20:
            counter = 0
            if chain is not None:
                head = (
                    f"\n\n\nRESULTS: for {framea} to {frameb}\nChain is: {' -> '.join(chain)}\n"
                    f"Net delay     avg = {avg_diff:g}: max = {max_diff:g}\n"
                )
            else:
                head = "\n\n\nRESULTS: for all Frames\n"
            frames, heading, nodes = books.report(chain)
            sys.stdout.write(head + frames)
            sys.stdout.flush()
            sys.stderr.write(heading)
            sys.stderr.flush()
            sys.stdout.write(nodes)
            sys.stdout.flush()
    return 0


console_main = entry(main)

if __name__ == "__main__":
    console_main()
