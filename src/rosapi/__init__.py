"""The ROS interface package ``rosapi``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/rosapi/``. ``rosapi.msg`` and ``rosapi.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
