"""The ROS interface package ``sensor_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/sensor_msgs/``. ``sensor_msgs.msg`` and ``sensor_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
