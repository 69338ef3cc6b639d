"""The ROS interface package ``gazebo_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/gazebo_msgs/``. ``gazebo_msgs.msg`` and ``gazebo_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
