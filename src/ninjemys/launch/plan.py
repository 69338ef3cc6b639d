"""The launch plan: what a set of launch files asks for, as plain data (no processes, no I/O).

``ninjemys.launch.xml`` builds it, ``ninjemys.launch.queries`` answers ``--nodes``/``--args``/
``--dump-params`` from it, ``ninjemys.launch.runner`` executes it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class Machine:
    """A ``<machine>``: where nodes may run (the local machine is the one named ``""``)."""

    name: str
    address: str
    env_loader: str | None = None
    ssh_port: int = 22
    user: str | None = None
    password: str | None = None
    assignable: bool = True
    timeout: float | None = None
    env_args: list[tuple[str, str]] = field(default_factory=list)

    @property
    def is_local(self) -> bool:
        """This machine: the implicit local machine, or an address that resolves to this host."""
        if self.name == "":
            return True
        from ninjemys.net.addresses import is_local_address

        return is_local_address(self.address)


@dataclass
class NodeSpec:
    """A ``<node>`` (or ``<test>``) with every attribute resolved."""

    package: str
    type: str
    name: str
    namespace: str = "/"
    args: str = ""
    machine_name: str | None = None
    respawn: bool = False
    respawn_delay: float = 0.0
    required: bool = False
    remap_args: list[tuple[str, str]] = field(default_factory=list)
    env_args: list[tuple[str, str]] = field(default_factory=list)
    output: str | None = None
    cwd: str | None = None
    launch_prefix: str | None = None
    filename: str = ""
    #: seconds between SIGINT and SIGTERM (and again to SIGKILL) at shutdown; None = the launch default
    sigint_timeout: float | None = None
    is_test: bool = False
    test_name: str | None = None
    time_limit: float | None = None
    retry: int | None = None

    @property
    def resolved_name(self) -> str:
        """``/ns/name`` as ``roslaunch --nodes`` prints it."""
        ns = self.namespace if self.namespace.endswith("/") else self.namespace + "/"
        return self.name if self.name.startswith("/") else ns + self.name


@dataclass(frozen=True)
class SetupCommand:
    """``<rosparam command="dump|delete">``: run against the parameter server before nodes start."""

    command: str
    param: str
    file: str | None = None


@dataclass
class LaunchPlan:
    """Everything the launch files ask for, in declaration order."""

    files: list[str] = field(default_factory=list)
    nodes: list[NodeSpec] = field(default_factory=list)
    tests: list[NodeSpec] = field(default_factory=list)
    params: dict[str, Any] = field(default_factory=dict)
    clear_params: list[str] = field(default_factory=list)
    machines: dict[str, Machine] = field(default_factory=lambda: {"": Machine("", "localhost")})
    setup_commands: list[SetupCommand] = field(default_factory=list)
    #: top-level args without a fixed value: name -> (doc, default), for ``--ros-args``
    arg_docs: dict[str, tuple[str | None, str | None]] = field(default_factory=dict)
    #: non-fatal problems (unknown tags/attributes, deprecations), printed as warnings like ROS 1
    warnings: list[str] = field(default_factory=list)

    def node_names(self) -> list[str]:
        return [n.resolved_name for n in self.nodes + self.tests if n.name]
