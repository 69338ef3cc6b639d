"""Robot descriptions: the URDF kinematic tree (:mod:`.kinematics`, pure) and robot_state_publisher
(:mod:`.state_publisher`, a node): joint states in, /tf and /tf_static out, as ROS 1's C++ node does."""
