"""ROS 1's ``dynamic_reconfigure.encoding``: configurations between dicts and Config messages."""

from ninjemys.dynamic_reconfigure.encoding import (
    Config,
    decode_config,
    decode_description,
    encode_config,
    encode_description,
    extract_params,
    get_tree,
    group_dict,
    initial_config,
)

__all__ = [
    "Config",
    "decode_config",
    "decode_description",
    "encode_config",
    "encode_description",
    "extract_params",
    "get_tree",
    "group_dict",
    "initial_config",
]
