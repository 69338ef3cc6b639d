"""The ROS interface package ``std_msgs``: message and service classes, generated on first import.

The definitions live in ``ninjemys/interfaces/std_msgs/``; ``std_msgs.msg`` and ``std_msgs.srv`` are lazy modules whose
classes are compiled from them the first time a name is looked up, so importing this package costs nothing.
"""
