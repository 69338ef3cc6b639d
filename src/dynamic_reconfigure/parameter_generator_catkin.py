"""``from dynamic_reconfigure.parameter_generator_catkin import *``: the API .cfg files use."""

from ninjemys.dynamic_reconfigure.generator import ParameterGenerator, bool_t, double_t, int_t, str_t

__all__ = ["ParameterGenerator", "bool_t", "double_t", "int_t", "str_t"]
