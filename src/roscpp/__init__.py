"""The ROS interface package ``roscpp``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/roscpp/``. ``roscpp.msg`` and ``roscpp.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
