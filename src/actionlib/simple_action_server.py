"""``actionlib.simple_action_server``: SimpleActionServer (ROS 1's API)."""

from __future__ import annotations

from collections.abc import Callable

from actionlib import _process
from ninjemys.actionlib import simple_server as _core

TYPE_CHECKING = False
if TYPE_CHECKING:
    from typing import Any

__all__ = ["SimpleActionServer"]


class SimpleActionServer(_core.SimpleActionServer):
    """``SimpleActionServer(name, ActionSpec, execute_cb=None, auto_start=True)``."""

    def __init__(
        self,
        name: str,
        ActionSpec: Any,  # noqa: N803 - ROS 1's signature
        execute_cb: Callable[[Any], Any] | None = None,
        auto_start: bool = True,
    ) -> None:
        super().__init__(
            _process.node(),
            name,
            ActionSpec,
            execute_cb,
            auto_start,
        )
