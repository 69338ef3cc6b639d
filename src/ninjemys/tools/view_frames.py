"""``rosrun tf2_tools view_frames.py``: listen to tf for 5 s, then draw the frame tree.

Like ROS 1's it asks its own ``~tf2_frames`` service for the buffer's YAML and writes ``frames.gv``
(Graphviz, the same text ROS 1 writes) in the current directory, then ``frames.pdf`` with
Graphviz's ``dot`` when it is installed. Without ``dot`` it writes ``frames.svg`` instead, laid out
here (a layered tree, edges labelled as in the PDF), which any browser opens; it says which it wrote.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import time
from html import escape
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ninjemys.tools.cli import entry

if TYPE_CHECKING:
    from ninjemys.node import Node

LISTEN_SECONDS = 5.0


def generate_dot(data: dict[str, dict[str, Any]], now: float) -> str:
    """tf2_tools' Graphviz text for the ``all_frames_as_yaml`` mapping."""
    if not data:
        return 'digraph G { "No tf data received" }'
    parts = ["digraph G {\n"]
    root = ""
    for child, info in data.items():
        parts.append(
            f'"{info["parent"]}" -> "{child}"[label=" Broadcaster: {info["broadcaster"]}\\n'
            f"Average rate: {info['rate']}\\nBuffer length: {info['buffer_length']}\\n"
            f"Most recent transform: {info['most_recent_transform']}\\n"
            f'Oldest transform: {info["oldest_transform"]}\\n"];\n'
        )
        if info["parent"] not in data:
            root = info["parent"]
    parts.append("edge [style=invis];\n")
    parts.append(' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n')
    parts.append(f'"Recorded at time: {now}"[ shape=plaintext ] ;\n')
    parts.append(f'}}->"{root}";\n}}')
    return "".join(parts)


def _label(info: dict[str, Any]) -> list[str]:
    """The five lines tf2_tools puts on an edge."""
    return [
        f"Broadcaster: {info['broadcaster']}",
        f"Average rate: {info['rate']}",
        f"Buffer length: {info['buffer_length']}",
        f"Most recent transform: {info['most_recent_transform']}",
        f"Oldest transform: {info['oldest_transform']}",
    ]


def edges_from_yaml(data: dict[str, dict[str, Any]]) -> list[tuple[str, str, list[str]]]:
    """``(parent, child, label lines)`` of every frame in ``all_frames_as_yaml``'s mapping."""
    return [(str(info["parent"]), str(child), _label(info)) for child, info in data.items()]


_DOT_EDGE = re.compile(r'^"([^"]*)" -> "([^"]*)"\[label="(.*)"\];$', re.MULTILINE)


def edges_from_dot(dot: str) -> list[tuple[str, str, list[str]]]:
    """The labelled edges of tf's ``allFramesAsDot`` text."""
    return [
        (m[1], m[2], [line.strip() for line in m[3].split("\\n") if line.strip()])
        for m in _DOT_EDGE.finditer(dot)
    ]


def generate_svg(edges: list[tuple[str, str, list[str]]], now: float) -> str:
    """The frame tree as a standalone SVG: frames as ellipses, parents above children, labelled edges."""
    children: dict[str, list[str]] = {}
    child_names = {child for _, child, _ in edges}
    for parent, child, _ in edges:
        children.setdefault(parent, []).append(child)
    roots = [p for p in children if p not in child_names] or list(children)[:1]
    pos: dict[str, tuple[float, int]] = {}
    next_x = [0.0]

    def place(frame: str, depth: int, seen: set[str]) -> float:
        seen.add(frame)
        kids = [k for k in children.get(frame, []) if k not in seen]
        if not kids:
            x = next_x[0]
            next_x[0] += 1.0
        else:
            xs = [place(k, depth + 1, seen) for k in kids]
            x = sum(xs) / len(xs)
        pos[frame] = (x, depth)
        return x

    seen: set[str] = set()
    for r in roots:
        place(r, 0, seen)
    longest = max((len(line) for _, _, label in edges for line in label), default=10)
    col, row = max(180.0, 2.0 * (longest * 5.4 + 16)), 150.0
    width = max(1.0, next_x[0]) * col + 40
    height = (max((d for _, d in pos.values()), default=0) + 1) * row + 60
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'font-family="sans-serif" font-size="11">',
        '<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="7" markerHeight="7" '
        'orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z"/></marker></defs>',
        f'<text x="10" y="{height - 15:.0f}">view_frames Result — Recorded at time: {now:.3f}</text>',
    ]

    def xy(frame: str) -> tuple[float, float]:
        x, d = pos[frame]
        return 20 + x * col + col / 2, 40 + d * row

    for parent, child, label in edges:
        if parent not in pos or child not in pos:
            continue
        (x1, y1), (x2, y2) = xy(parent), xy(child)
        out.append(
            f'<line x1="{x1:.1f}" y1="{y1 + 18:.1f}" x2="{x2:.1f}" y2="{y2 - 18:.1f}" stroke="black" '
            'marker-end="url(#arrow)"/>'
        )
        lx, ly = (x1 + x2) / 2 + 6, (y1 + y2) / 2 - 30
        for i, line in enumerate(label):
            out.append(f'<text x="{lx:.1f}" y="{ly + 12 * i:.1f}" font-size="9">{escape(line)}</text>')
    for frame in pos:
        x, y = xy(frame)
        out.append(f'<ellipse cx="{x:.1f}" cy="{y:.1f}" rx="70" ry="18" fill="white" stroke="black"/>')
        out.append(f'<text x="{x:.1f}" y="{y + 4:.1f}" text-anchor="middle">{escape(frame)}</text>')
    out.append("</svg>\n")
    return "\n".join(out)


def write_outputs(data: dict[str, dict[str, Any]], now: float, directory: Path) -> list[Path]:
    """tf2_tools' files: frames.gv and frames.pdf (with dot) or frames.svg (without)."""
    return write_graph(generate_dot(data, now), edges_from_yaml(data), now, directory)


def write_graph(
    dot_text: str, edges: list[tuple[str, str, list[str]]], now: float, directory: Path
) -> list[Path]:
    """Write ``dot_text`` to frames.gv, then frames.pdf with Graphviz's dot if it is installed, else
    frames.svg drawn from ``edges``; returns the files written."""
    gv = directory / "frames.gv"
    gv.write_text(dot_text)
    written = [gv]
    dot = shutil.which("dot")
    if dot is not None:
        pdf = directory / "frames.pdf"
        subprocess.run([dot, "-Tpdf", str(gv), "-o", str(pdf)], check=False)
        if pdf.exists():
            written.append(pdf)
            return written
    svg = directory / "frames.svg"
    svg.write_text(generate_svg(edges, now))
    written.append(svg)
    return written


def main(argv: list[str] | None = None) -> int:
    """tf2_tools' ``view_frames``: listen 5 s, then write the buffer's frame graph."""
    from ninjemys.node.run import run_main

    return run_main("view_frames", sys.argv[1:] if argv is None else argv, _tf2_view)


def _tf2_view(node: Node) -> int:
    import yaml

    from ninjemys.tf2.core import BufferCore
    from ninjemys.tf2.node import TransformListener

    node.log.info("Listening to tf data during 5 seconds...")
    buffer = BufferCore()
    TransformListener(node, buffer, now=node.get_time, report=node.log.warn)
    node.sleep(LISTEN_SECONDS)
    node.log.info("Generating graph in frames.pdf file...")
    # ROS 1's script asks its own ~tf2_frames service for this YAML: the same text, straight from the buffer
    data = yaml.safe_load(buffer.all_frames_as_yaml()) or {}
    written = write_outputs(data, node.get_time(), Path.cwd())
    if not any(p.suffix == ".pdf" for p in written):
        node.log.info(
            "Graphviz's dot is not installed: wrote frames.gv and frames.svg (open it in a browser)"
        )
    return 0


def tf_main(argv: list[str] | None = None) -> int:
    """tf's deprecated ``view_frames`` (``[--node NAME]``): tf's dot text, from its own listener or from
    a node's ``tf_frames`` service."""
    import argparse

    from ninjemys.names import strip_remap_args
    from ninjemys.node.run import run_main

    argv = sys.argv[1:] if argv is None else argv
    parser = argparse.ArgumentParser(prog="view_frames", usage="usage: view_frames [options]")
    parser.add_argument("--node", metavar="node name", help="Node to get frames from")
    options = parser.parse_args(strip_remap_args(["view_frames", *argv])[1:])
    return run_main("view_frames", argv, lambda node: _tf_view(node, options.node), anonymous=True)


def _tf_view(node: Node, of_node: str | None) -> int:
    from ninjemys.errors import NinjemysError
    from ninjemys.idl.loader import get_service_class
    from ninjemys.tf2.core import BufferCore
    from ninjemys.tf2.node import TransformListener

    if of_node:
        print("Generating graph for node: ", of_node)
        service = f"{of_node}/tf_frames"
        print(f"Waiting for service {service}")
        node.wait_for_service(service)
        print("Polling service")
        try:
            dot_text = node.service_proxy(service, get_service_class("tf/FrameGraph"))().dot_graph
        except (NinjemysError, OSError) as e:
            print(f"Service call failed: {e}")
            return 1
    else:
        buffer = BufferCore()
        TransformListener(node, buffer, now=node.get_time, report=node.log.warn)
        print("WARNING: tf view_frames is deprecated. Use tf2_tools view_frames.py instead.")
        print(f"Listening to /tf for {LISTEN_SECONDS} seconds")
        time.sleep(LISTEN_SECONDS)
        print("Done Listening")
        dot_text = buffer.all_frames_as_dot(node.get_time())
    written = write_graph(dot_text, edges_from_dot(dot_text), node.get_time(), Path.cwd())
    if written[-1].suffix == ".pdf":
        print("frames.pdf generated")
    else:
        print(
            "Graphviz's dot is not installed: wrote frames.gv and frames.svg (open it in a browser)",
            file=sys.stderr,
        )
    return 0


tf_console_main = entry(tf_main)


console_main = entry(main)

if __name__ == "__main__":
    console_main()
