"""The ROS interface package ``control_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/control_msgs/``. ``control_msgs.msg`` and ``control_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
