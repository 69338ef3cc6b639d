"""A robot description (URDF after xacro) read as the simulator needs it.

``xmltree`` parses with line numbers, ``geometry`` reads the links and joints (wheels, footprint,
sensor link poses, colour), ``gazebo`` reads the ``<gazebo>`` extension blocks (drive, sensors,
ros_control) and ``build`` joins them into one :class:`ninjemys.sim.robot_model.RobotModel`.
"""
