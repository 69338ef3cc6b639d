"""ros_control inside the simulator: controller_manager, joint_state_controller, diff_drive_controller.

Gazebo runs ros_control in-process (gazebo_ros_control): each physics step the robot hardware is read,
the running controllers update, and their joint commands are written back. The simulator node does the
same through :class:`ninjemys.sim.ros_control.hardware.ControlLoop` (one call per step). ``odometry``
and ``limits`` are the controllers' arithmetic without ROS; ``manager`` gives the controller_manager
services; ``spawner`` is ``rosrun controller_manager spawner``.
"""
