"""tf2 without ROS inside: the buffer core (:mod:`.core`), transform math on tuples (:mod:`.math`),
the message-level buffer (:mod:`.buffer`), TFMessage wire decoding (:mod:`.wire`), the node-level
listener and broadcasters (:mod:`.node`) and tf's classic ``transformations`` module.

The ROS 1 module names (``tf2_ros``, ``tf2_py``, ``tf2_geometry_msgs``, ``tf``) are thin facades
over these. Nothing is imported here so that ``import ninjemys.tf2.math`` stays cheap.
"""
