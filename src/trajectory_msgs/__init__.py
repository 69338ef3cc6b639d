"""The ROS interface package ``trajectory_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/trajectory_msgs/``. ``trajectory_msgs.msg`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
