"""The ROS interface package ``rospy_tutorials``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/rospy_tutorials/``. ``rospy_tutorials.msg`` and ``rospy_tutorials.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
