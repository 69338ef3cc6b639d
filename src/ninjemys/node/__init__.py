"""The node runtime: ``Node`` and the handles made from it (publishers, subscribers, services).

``from ninjemys.node import Node``; everything else is reached through a Node's methods.
"""

from __future__ import annotations

from ninjemys.node.node import Node

__all__ = ["Node"]
