"""Drivers for the robot's devices, with ROS 1's package, node, topic and parameter names.

Each driver is pure Python on the device's published protocol (the Linux joystick API, ...): a
module with no node that decodes the device and keeps its state, tested on emulated devices, and a
node module that binds it to ROS through the core ``Node``. Drivers are apps: peers of ``sim`` and
``nav``, importing neither.
"""
