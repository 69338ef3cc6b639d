"""The ROS interface package ``realsense2_camera``, shipped with ninjemys.

Its definitions live in ``ninjemys/interfaces/realsense2_camera/``. ``realsense2_camera.msg`` and ``realsense2_camera.srv`` are lazy modules: a class is
generated from its definition the first time its name is looked up, so importing this package costs nothing.
"""
