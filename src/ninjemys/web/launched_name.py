"""The node name, namespace and remappings a page tool (rviz, rqt_*) takes from its command line.

roslaunch starts ``<node pkg="rviz" type="rviz" name="rviz" ns="robot1"><remap .../></node>`` as
``rviz __name:=rviz __ns:=/robot1 from:=to``. rviz and rqt ask for an anonymous node, but in ROS 1 a
``__name:=`` cancels that (roscpp's and rospy's rule), so the tool is ``/robot1/rviz`` on the graph,
``rosnode kill /rviz`` finds it, and its remappings apply. This reads those arguments the way a
node does (:mod:`ninjemys.node.cli_args`) and gives what :class:`ninjemys.node.Node` takes.
"""

from __future__ import annotations

from dataclasses import dataclass

from ninjemys.node import Node
from ninjemys.node.cli_args import parse_args


@dataclass(frozen=True)
class LaunchedName:
    """What to register the tool's node as."""

    name: str
    namespace: str
    remappings: dict[str, str]
    anonymous: bool

    @classmethod
    def anonymous_default(cls, name: str) -> LaunchedName:
        """The tool started by hand with no node arguments: ``name``, anonymous, at the root."""
        return cls(name, "/", {}, anonymous=True)

    def node(self, master_uri: str) -> Node:
        """The tool's node, registered under this name (the same for every page tool)."""
        return Node(
            self.name,
            namespace=self.namespace,
            anonymous=self.anonymous,
            remappings=self.remappings,
            master_uri=master_uri,
        )


def launched_name(default: str, argv: list[str]) -> LaunchedName:
    """``default`` made anonymous, unless ``__name:=`` names the node; ``__ns:=`` / ROS_NAMESPACE
    and ``from:=to`` remappings as a node reads them (``argv`` without the program name)."""
    args = parse_args([default, *argv], strict_names=False)
    return LaunchedName(
        name=args.name if args.name is not None else default,
        namespace=args.namespace,
        remappings=dict(args.remappings),
        anonymous=args.name is None,
    )


__all__ = ["LaunchedName", "launched_name"]
