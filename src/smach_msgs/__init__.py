"""The ROS interface package ``smach_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/smach_msgs/``. ``smach_msgs.msg`` is a lazy module: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
