"""The full definition text (``message_definition``) exactly as genmsg ``compute_full_text`` builds it.

Own text first, then for every message type it depends on (depth-first, in order of first appearance,
each once) a line of 80 ``=``, ``MSG: pkg/Type`` and that type's text; the one trailing newline the
concatenation leaves is dropped. Publishers send it in the connection header and bags store it, so
peers can decode types they were never built with (:func:`parse_full_text` is the inverse).
"""

from __future__ import annotations

from ninjemys.errors import DefinitionError
from ninjemys.idl.md5 import Lookup
from ninjemys.idl.spec import MsgSpec

SEPARATOR = "=" * 80


def all_dependencies(spec: MsgSpec, lookup: Lookup) -> list[str]:
    """Every nested message type of ``spec``, depth-first, in order of first appearance."""
    order: dict[str, None] = {}

    def visit(s: MsgSpec) -> None:
        for dep in s.dependencies:
            if dep not in order:
                order[dep] = None
                visit(lookup(dep))
            else:
                # genmsg appends the whole subtree again, then keeps the first occurrence of each:
                # the subtree of an already-seen type adds nothing new, so skipping it is equivalent
                continue

    visit(spec)
    return list(order)


def compute_full_text(spec: MsgSpec, lookup: Lookup) -> str:
    parts = [spec.text, "\n"]
    for dep in all_dependencies(spec, lookup):
        parts.append(f"{SEPARATOR}\nMSG: {dep}\n")
        parts.append(lookup(dep).text)
        parts.append("\n")
    return "".join(parts)[:-1]


def split_full_text(type_name: str, full_text: str) -> dict[str, str]:
    """Split a full text into ``{"pkg/Type": text}`` for the main type and every embedded one.

    Texts come back as the block between separators (the trailing newline that compute_full_text
    adds before a separator is removed), which parses to the same fields and constants.
    """
    blocks: dict[str, str] = {}
    current = type_name
    lines: list[str] = []
    for line in full_text.split("\n"):
        if line.strip() == SEPARATOR:
            blocks[current] = "\n".join(lines)
            current, lines = "", []
            continue
        if not current:
            if not line.startswith("MSG:"):
                raise DefinitionError(
                    f"message definition of {type_name}: expected 'MSG: pkg/Type' after a separator, "
                    f"got {line!r}"
                )
            current = line[4:].strip()
            continue
        lines.append(line)
    if not current:
        raise DefinitionError(f"message definition of {type_name}: separator without a 'MSG:' line")
    blocks[current] = "\n".join(lines)
    return blocks
