"""The ROS interface package ``map_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/map_msgs/``. ``map_msgs.msg`` and ``map_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
