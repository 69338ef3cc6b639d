"""genpy.dynamic: message classes from a full message text (a bag's or a connection header's
``message_definition``) for types no package on this machine defines, over ninjemys.idl's loader."""

from __future__ import annotations

from typing import Any

from ninjemys.errors import NinjemysError
from ninjemys.idl.fulltext import SEPARATOR, split_full_text
from ninjemys.idl.loader import message_class_from_definition

__all__ = ["generate_dynamic", "MsgGenerationException"]


class MsgGenerationException(Exception):
    """The text is not a valid (concatenated) message definition (genmsg's exception in ROS 1)."""


def generate_dynamic(core_type: str, msg_cat: str) -> dict[str, Any]:
    """``{type: class}`` for ``core_type`` and every type embedded in its full text ``msg_cat``
    (``gendeps --cat`` output: the core definition, then ``MSG: pkg/Type`` blocks)."""
    msg_cat = msg_cat.replace("roslib/Header", "std_msgs/Header")
    try:
        blocks = split_full_text(core_type, msg_cat)
        classes = {}
        for name, text in blocks.items():
            # each type's own full text: its block first, the others embedded after it
            others = "".join(f"\n{SEPARATOR}\nMSG: {n}\n{t}" for n, t in blocks.items() if n != name)
            classes[name] = message_class_from_definition(name, text + others)
    except (NinjemysError, ValueError) as exc:
        raise MsgGenerationException(str(exc)) from None
    return classes
