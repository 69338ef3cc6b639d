"""The ROS interface package ``fiducial_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/fiducial_msgs/``. ``fiducial_msgs.msg`` and ``fiducial_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
