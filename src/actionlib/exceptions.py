"""``actionlib.exceptions``: ROS 1's ActionException (a class given as an action is not one)."""

from ninjemys.errors import ActionException

__all__ = ["ActionException"]
