"""The ROS interface package ``diagnostic_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/diagnostic_msgs/``. ``diagnostic_msgs.msg`` and ``diagnostic_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
