"""The ROS interface package ``stereo_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/stereo_msgs/``. ``stereo_msgs.msg`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
