"""``actionlib``: ROS 1's action library, and the ROS interface package of its test actions.

``actionlib.msg`` is a lazy module (the Test, TestRequest and TwoInts actions); its definitions live in
``ninjemys/interfaces/actionlib/``.
"""
