"""interactive_markers as provided by ninjemys: the Python server side of ROS 1's interactive markers.

Course and tutorial code (``basic_controls.py``, Cartesian teleoperation exercises) builds markers
with ``InteractiveMarkerServer`` and ``MenuHandler`` and lets rviz move them. The modules keep
ROS 1's names (``interactive_markers.interactive_marker_server``, ``interactive_markers.menu_handler``),
topics (``<ns>/update``, ``<ns>/update_full``, ``<ns>/feedback``) and message types, and run on the
node of ``rospy.init_node``.
"""
