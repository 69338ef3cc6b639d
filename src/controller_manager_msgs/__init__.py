"""The ROS interface package ``controller_manager_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/controller_manager_msgs/``. ``controller_manager_msgs.msg`` and ``controller_manager_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
