"""The ROS interface package ``geometry_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/geometry_msgs/``. ``geometry_msgs.msg`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
