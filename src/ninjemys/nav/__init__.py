"""The navigation stack: map_server, slam_gmapping, amcl, move_base and the safety monitor.

The algorithms (map files, costmaps, planners, particle filter, mapping) are numpy modules with no ROS
inside; the ``*_node`` modules bind them to ROS 1's topics, services, actions and parameters.
"""
