"""The ROS interface package ``rosserial_msgs``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/rosserial_msgs/``. ``rosserial_msgs.msg`` and ``rosserial_msgs.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
