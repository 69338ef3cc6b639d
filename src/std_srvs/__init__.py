"""The ROS interface package ``std_srvs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/std_srvs/``. ``std_srvs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
