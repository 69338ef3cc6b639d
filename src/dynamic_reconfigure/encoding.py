"""ROS 1's ``dynamic_reconfigure.encoding``: configurations between dicts and Config messages."""

from dynamic_reconfigure.msg import (
    BoolParameter,
    DoubleParameter,
    GroupState,
    IntParameter,
    ParamDescription,
    StrParameter,
)
from dynamic_reconfigure.msg import Config as ConfigMsg
from dynamic_reconfigure.msg import ConfigDescription as ConfigDescrMsg
from dynamic_reconfigure.msg import Group as GroupMsg
from ninjemys.dynamic_reconfigure.encoding import (
    Config,
    decode_config,
    decode_description,
    encode_config,
    encode_description,
    encode_groups,
    extract_params,
    get_parents,
    get_tree,
    group_dict,
    initial_config,
)

__all__ = [
    "BoolParameter",
    "Config",
    "ConfigDescrMsg",
    "ConfigMsg",
    "DoubleParameter",
    "GroupMsg",
    "GroupState",
    "IntParameter",
    "ParamDescription",
    "StrParameter",
    "decode_config",
    "decode_description",
    "encode_config",
    "encode_description",
    "encode_groups",
    "extract_params",
    "get_parents",
    "get_tree",
    "group_dict",
    "initial_config",
]
