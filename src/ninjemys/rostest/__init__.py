"""rostest and rosunit: the ROS 1 way to run a package's tests (``rostest pkg file.test``,
``rostest.rosrun(...)`` inside a test node), with JUnit XML results where ROS 1 writes them.

:mod:`.junit` reads and writes the result files, :mod:`.pyunit` runs a Python ``unittest`` suite as
a rostest/rosunit test does; the ``rostest`` command is :mod:`ninjemys.tools.rostest`, the
``import rostest`` / ``import rosunit`` facades are the top-level packages.
"""
