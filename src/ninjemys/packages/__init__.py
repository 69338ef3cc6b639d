"""Packages and workspaces: package.xml, discovery, the catkin_make builder and the shipped packages.

``manifest`` parses package.xml (formats 1-3), ``discovery`` finds packages on ROS_PACKAGE_PATH, in
workspaces and inside ninjemys itself, ``executables`` finds what ``rosrun``/``roslaunch`` start,
``workspace`` and ``builder`` implement ``catkin_make``, ``setup_scripts`` writes devel/setup.*.
"""
