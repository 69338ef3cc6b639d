"""The ROS interface package ``tf2_web_republisher``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/tf2_web_republisher/``. ``tf2_web_republisher.msg`` and ``tf2_web_republisher.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
