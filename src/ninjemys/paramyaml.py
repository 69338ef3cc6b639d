"""The YAML dialect of ROS parameters, shared by rosparam, roslaunch ``<rosparam>`` and ``_p:=v`` args.

It is YAML 1.1 (PyYAML's safe loader) plus what rosparam registers: ``!degrees``/``!radians`` tags,
implicit ``rad(pi/2)`` / ``deg(90)`` scalars, and ``!!binary`` values (``bytes``, sent as XML-RPC base64).
Dumping prints what ROS 1's ``rosparam get/dump`` print (PyYAML's block style, non-ASCII escaped).

PyYAML is imported only when needed (:mod:`ninjemys.paramyaml_pyyaml`): parsing always needs it, dumping
rarely does (:mod:`ninjemys.paramyaml_emit` prints parameter trees itself), which keeps ~25 ms out of
``rosparam get`` and of every tool that merely might parse YAML.
"""

from __future__ import annotations

from ninjemys.errors import ParameterError

TYPE_CHECKING = False  # importing typing costs ~7 ms of a tool's start-up
if TYPE_CHECKING:
    from typing import Any


class ParamYamlError(ParameterError):
    """YAML text that does not parse; the message carries the line and column of the mistake."""


def load_yaml(text: str) -> Any:
    """Parse one YAML value; raises ParamYamlError naming the line and column of a mistake."""
    from ninjemys import paramyaml_pyyaml

    return paramyaml_pyyaml.load(text)


def load_yaml_documents(text: str) -> list[Any]:
    """Parse every document of a (possibly multi-document) YAML file."""
    from ninjemys import paramyaml_pyyaml

    return paramyaml_pyyaml.load_all(text)


def dump_yaml(value: Any) -> str:
    """Block-style YAML exactly as ROS 1's rosparam prints it (keys sorted, non-ASCII escaped)."""
    from ninjemys import paramyaml_emit

    text = paramyaml_emit.dump(value)
    if text is None:
        from ninjemys import paramyaml_pyyaml

        text = paramyaml_pyyaml.dump(value)
    return text
