"""The ROS interface package ``nav_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/nav_msgs/``. ``nav_msgs.msg`` and ``nav_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
