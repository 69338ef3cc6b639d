"""The ROS interface package ``tf2_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/tf2_msgs/``. ``tf2_msgs.msg`` and ``tf2_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
