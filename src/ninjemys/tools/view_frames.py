"""``rosrun tf2_tools view_frames.py``: listen to tf for 5 s, then draw the frame tree.

Like ROS 1's it asks its own ``~tf2_frames`` service for the buffer's YAML and writes ``frames.gv``
(Graphviz, the same text ROS 1 writes) in the current directory, then ``frames.pdf`` with
Graphviz's ``dot`` when it is installed. Without ``dot`` it writes ``frames.svg`` instead, laid out
here (a layered tree, edges labelled as in the PDF), which any browser opens; it says which it wrote.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from html import escape
from pathlib import Path
from typing import Any

from ninjemys.tools.cli import entry

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


def generate_svg(data: dict[str, dict[str, Any]], now: float) -> str:
    """The frame tree as a standalone SVG: frames as ellipses, parents above children, labelled edges."""
    children: dict[str, list[str]] = {}
    for child, info in data.items():
        children.setdefault(str(info["parent"]), []).append(str(child))
    roots = [p for p in children if p not in data] or list(children)[:1]
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
    col, row = 230.0, 150.0
    width = max(1.0, next_x[0]) * col + 40
    height = (max((d for _, d in pos.values()), default=0) + 1) * row + 60
    out = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0f}" height="{height:.0f}" '
        f'font-family="sans-serif" font-size="11">',
        f'<text x="10" y="{height - 15:.0f}">view_frames Result — Recorded at time: {now:.3f}</text>',
    ]

    def xy(frame: str) -> tuple[float, float]:
        x, d = pos[frame]
        return 20 + x * col + col / 2, 40 + d * row

    for child, info in data.items():
        parent = str(info["parent"])
        if parent not in pos or str(child) not in pos:
            continue
        (x1, y1), (x2, y2) = xy(parent), xy(str(child))
        out.append(
            f'<line x1="{x1:.1f}" y1="{y1 + 18:.1f}" x2="{x2:.1f}" y2="{y2 - 18:.1f}" stroke="black"/>'
        )
        label = [
            f"Broadcaster: {info['broadcaster']}",
            f"Average rate: {info['rate']}",
            f"Buffer length: {info['buffer_length']}",
            f"Most recent transform: {info['most_recent_transform']}",
            f"Oldest transform: {info['oldest_transform']}",
        ]
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
    """Write frames.gv and frames.pdf (with dot) or frames.svg (without); returns what was written."""
    gv = directory / "frames.gv"
    gv.write_text(generate_dot(data, now))
    written = [gv]
    dot = shutil.which("dot")
    if dot is not None:
        pdf = directory / "frames.pdf"
        subprocess.run([dot, "-Tpdf", str(gv), "-o", str(pdf)], check=False)
        if pdf.exists():
            written.append(pdf)
            return written
    svg = directory / "frames.svg"
    svg.write_text(generate_svg(data, now))
    written.append(svg)
    return written


def main(argv: list[str] | None = None) -> int:
    import yaml

    import rospy
    import tf2_ros
    from tf2_msgs.srv import FrameGraph

    full = ["view_frames", *(sys.argv[1:] if argv is None else argv)]
    rospy.init_node("view_frames", argv=full)
    rospy.loginfo("Listening to tf data during 5 seconds...")
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    rospy.sleep(LISTEN_SECONDS)
    rospy.loginfo("Generating graph in frames.pdf file...")
    rospy.wait_for_service("~tf2_frames")
    data = yaml.safe_load(rospy.ServiceProxy("~tf2_frames", FrameGraph)().frame_yaml) or {}
    written = write_outputs(data, rospy.Time.now().to_sec(), Path.cwd())
    if not any(p.suffix == ".pdf" for p in written):
        rospy.loginfo(
            "Graphviz's dot is not installed: wrote frames.gv and frames.svg (open it in a browser)"
        )
    return 0


console_main = entry(main)

if __name__ == "__main__":
    console_main()
