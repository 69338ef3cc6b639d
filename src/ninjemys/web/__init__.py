"""The browser apps: rviz, rqt and its plugins, the node graph (rqt_graph), and the simulators' views.

Each command (``rviz``, ``rqt_*``, ``rqt_graph``, ``turtlesim_node``, ``sim_node``) serves static
pages (``static/``) from one :class:`~ninjemys.web.app.WebApp` and mounts the gateway
(:mod:`ninjemys.bridge`) on it. This is the top floor of the wing: web may import the gateway and the
simulators it draws, and nothing below imports web. See docs/rviz.md, docs/rqt.md, docs/sim_web.md and
docs/architecture.md.
"""
