"""``URDF.from_parameter_server()``, which Noetic's urdf_parser_py has and the PyPI release lacks.

ninjemys takes urdf_parser_py from its upstream PyPI release (urdfdom-py, the ROS 2 line), which
dropped the one rospy-dependent call ROS 1 code uses: ``URDF.from_parameter_server(key)``, the robot
description read from the parameter server. ``import rospy`` gives it back: it adds the classmethod
to ``urdf_parser_py.urdf.Robot`` (``URDF`` is the same class) now if that module is loaded, or right
after it loads through a finder that answers for that one module name only.

As in Noetic, it works before ``rospy.init_node`` (the parameter is read as ``/unnamed``).
"""

from __future__ import annotations

import sys

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

MODULE = "urdf_parser_py.urdf"


def from_parameter_server(cls: Any, key: str = "robot_description") -> Any:
    """Parse the URDF XML held by parameter ``key`` (KeyError when it is not set, as in ROS 1)."""
    from rospy.client import get_param

    return cls.from_xml_string(get_param(key))


def add_to(module: Any) -> None:
    """Give ``module.Robot`` the classmethod, unless it has one of its own (Noetic's own release)."""
    robot = getattr(module, "Robot", None)
    if robot is not None and not hasattr(robot, "from_parameter_server"):
        robot.from_parameter_server = classmethod(from_parameter_server)


class _Loader:
    """Runs the real loader, then adds the classmethod."""

    def __init__(self, loader: Any) -> None:
        self.loader = loader

    def create_module(self, spec: Any) -> Any:
        return self.loader.create_module(spec)

    def exec_module(self, module: Any) -> None:
        self.loader.exec_module(module)
        add_to(module)


class UrdfFinder:
    """A MetaPathFinder for ``urdf_parser_py.urdf`` alone: the normal spec with :class:`_Loader`."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> Any:
        if fullname != MODULE:
            return None
        from importlib.machinery import PathFinder

        spec: Any = PathFinder.find_spec(fullname, path)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        spec.loader = _Loader(spec.loader)
        return spec


def install() -> None:
    """Add the classmethod now, or when urdf_parser_py.urdf loads (idempotent)."""
    module = sys.modules.get(MODULE)
    if module is not None:
        add_to(module)
        return
    if not any(isinstance(finder, UrdfFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, UrdfFinder())
