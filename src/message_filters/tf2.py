"""tf2_ros' MessageFilter for Python: ``MessageFilter(sub, tf_buffer, "map", queue_size=100)``."""

from ninjemys.message_filters.tf2 import FilterFailureReason, MessageFilter

__all__ = ["FilterFailureReason", "MessageFilter"]
