"""The ROS interface package ``turtlesim``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/turtlesim/``. ``turtlesim.msg`` and ``turtlesim.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
