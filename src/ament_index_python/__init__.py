"""The one ``ament_index_python`` call the upstream xacro release makes, answered with ROS 1's rules.

The xacro library on PyPI (the upstream ros/xacro project) resolves ``$(find pkg)`` by calling
``ament_index_python.packages.get_package_share_directory``. On ROS 1 ``$(find pkg)`` is ``rospack
find``: the workspaces on ROS_PACKAGE_PATH, then the packages ninjemys ships. Providing that call
here makes ``xacro.process_file`` in a user's own script resolve packages as Noetic's xacro does,
without touching xacro's code.
"""

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

__all__ = ["PackageNotFoundError", "get_package_share_directory"]
