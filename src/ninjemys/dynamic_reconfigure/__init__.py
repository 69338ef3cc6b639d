"""dynamic_reconfigure's core: configurations and descriptions as messages, the .cfg generator,
and the server and client that speak ROS 1's ``parameter_descriptions`` / ``parameter_updates``
topics and ``set_parameters`` service on a :class:`ninjemys.node.Node`."""
