"""``check_urdf FILE``: liburdfdom-tools' check, with the URDF's own file and line in each error.

The output is urdfdom's: ``robot name is: NAME``, the "Successfully Parsed XML" rule and the link
tree from the root; a failure is ``Error:   REASON`` / ``at line N in FILE`` / ``ERROR: Model
Parsing the xml failed`` with exit status 255. urdfdom's "at line" names its own C++ source line,
which tells a user nothing; ours names the line of the URDF element that is wrong. The rules are
the model checks urdfdom makes: a named robot, at least one link, unique names, joints naming
known links, limits on revolute and prismatic joints, one parent per link and exactly one root.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
import xml.parsers.expat
from dataclasses import dataclass, field

from ninjemys.errors import NinjemysError

USAGE = "Expect URDF xml file to parse"
FAILED = "ERROR: Model Parsing the xml failed"
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


class CheckFailed(NinjemysError):
    """One urdfdom-style error: the reason and the URDF line it is about."""

    def __init__(self, reason: str, line: int) -> None:
        super().__init__(reason)
        self.reason, self.line = reason, line


@dataclass
class Tree:
    name: str
    root: str
    children: dict[str, list[str]] = field(default_factory=dict)


def _parse(text: str) -> tuple[ET.Element, dict[int, int]]:
    """The document and the line each element starts on (keyed by ``id(element)``), via expat."""
    lines: dict[int, int] = {}
    builder = ET.TreeBuilder()
    expat = xml.parsers.expat.ParserCreate()

    def start(tag: str, attrs: dict[str, str]) -> None:
        lines[id(builder.start(tag, attrs))] = expat.CurrentLineNumber

    expat.StartElementHandler = start
    expat.EndElementHandler = builder.end
    try:
        expat.Parse(text, True)
    except xml.parsers.expat.ExpatError as exc:
        raise CheckFailed(f"malformed XML: {xml.parsers.expat.ErrorString(exc.code)}", exc.lineno) from None
    return builder.close(), lines


def check(text: str) -> Tree:
    """The link tree of a URDF document, or CheckFailed with urdfdom's reason and the URDF line."""
    if not text.strip():
        raise CheckFailed("Error document empty.", 0)
    root, lines = _parse(text)
    if root.tag != "robot":
        raise CheckFailed("Could not find the 'robot' element in the xml file", lines[id(root)])
    name = root.get("name")
    if not name:
        raise CheckFailed("No name given for the robot.", lines[id(root)])
    links: dict[str, int] = {}
    for link in root.findall("link"):
        link_name = link.get("name")
        if not link_name:
            raise CheckFailed("No name given for the link.", lines[id(link)])
        if link_name in links:
            raise CheckFailed(f"link '{link_name}' is not unique.", lines[id(link)])
        links[link_name] = lines[id(link)]
    if not links:
        raise CheckFailed("No link elements found in urdf file", lines[id(root)])
    parent_of: dict[str, str] = {}
    children: dict[str, list[str]] = {link: [] for link in links}
    seen: set[str] = set()
    for joint in root.findall("joint"):
        _check_joint(joint, lines[id(joint)], links, seen, parent_of, children)
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        names = ", ".join(roots) if roots else "none"
        raise CheckFailed(
            f"Failed to find root link: {len(roots)} links have no parent ({names})", lines[id(root)]
        )
    return Tree(name=name, root=roots[0], children=children)


def _check_joint(
    joint: ET.Element,
    line: int,
    links: dict[str, int],
    seen: set[str],
    parent_of: dict[str, str],
    children: dict[str, list[str]],
) -> None:
    name = joint.get("name")
    if not name:
        raise CheckFailed("unnamed joint found", line)
    if name in seen:
        raise CheckFailed(f"joint '{name}' is not unique.", line)
    seen.add(name)
    kind = joint.get("type")
    if kind not in JOINT_TYPES:
        raise CheckFailed(f"Joint [{name}] has no known type [{kind or ''}]", line)
    if kind in ("revolute", "prismatic") and joint.find("limit") is None:
        raise CheckFailed(f"Joint [{name}] is of type {kind.upper()} but it does not specify limits", line)
    ends = {}
    for end in ("parent", "child"):
        element = joint.find(end)
        link = element.get("link") if element is not None else None
        if not link:
            raise CheckFailed(f"No {end} link specified for joint [{name}]", line)
        if link not in links:
            raise CheckFailed(f"Failed to build tree: {end} link [{link}] of joint [{name}] not found", line)
        ends[end] = link
    child, parent = ends["child"], ends["parent"]
    if child in parent_of:
        raise CheckFailed(f"link [{child}] has two parents: [{parent_of[child]}] and [{parent}]", line)
    parent_of[child] = parent
    children[parent].append(child)


def render(tree: Tree) -> str:
    """urdfdom's printout: the robot name, the rule and each link's children, indented per level."""
    out = [f"robot name is: {tree.name}", "---------- Successfully Parsed XML ---------------"]
    out.append(f"root Link: {tree.root} has {len(tree.children[tree.root])} child(ren)")

    def walk(link: str, level: int) -> None:
        for number, child in enumerate(tree.children[link], start=1):
            out.append("  " * (level + 1) * 2 + f"child({number}):  {child}")
            walk(child, level + 1)

    walk(tree.root, 0)
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Check one URDF file; 0 when it parses, 255 (as urdfdom's check_urdf) when it does not."""
    args = sys.argv[1:] if argv is None else argv
    if not args:
        print(USAGE, file=sys.stderr)
        return 255
    path = args[0]
    try:
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
    except OSError as exc:
        text = ""
        print(f"Error:   could not read {path}: {exc.strerror}", file=sys.stderr)
        print(FAILED, file=sys.stderr)
        return 255
    try:
        tree = check(text)
    except CheckFailed as exc:
        print(f"Error:   {exc.reason}", file=sys.stderr)
        print(f"         at line {exc.line} in {path}", file=sys.stderr)
        print(FAILED, file=sys.stderr)
        return 255
    sys.stdout.write(render(tree))
    return 0


def console_main() -> None:
    """The ``check_urdf`` console script."""
    sys.exit(main())


if __name__ == "__main__":
    console_main()
