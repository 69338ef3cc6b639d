"""Occupancy-grid maps in ROS 1's map_server format (``map.yaml`` + image), shared by the navigation
stack (map_server, amcl, gmapping) and the simulator (worlds from a map, ``world_to_map``).

It lives below both so neither imports the other (they are peers, see docs/architecture.md):
:mod:`ninjemys.maps.mapfile` loads and saves maps and holds :class:`~ninjemys.maps.mapfile.GridMap`.
"""
