"""The WebSocket gateway: the browser's one data path to a ROS graph.

One endpoint speaks rosbridge v2 (roslibjs, roslibpy) and the Foxglove WebSocket protocol (rviz,
rqt, the graph page and the simulators' views); which one a client gets depends on the subprotocol
it offers. :mod:`~ninjemys.bridge.server` (``Gateway``, ``GatewayOptions``) runs it, on its own HTTP
server or mounted on the web app's; :mod:`~ninjemys.bridge.graph` taps ROS topics raw and calls
services; :mod:`~ninjemys.bridge.foxglove` and :mod:`~ninjemys.bridge.rosbridge` are the two
protocols; :mod:`~ninjemys.bridge.outbox` bounds what each client may queue. ``rosbridge_websocket``
and ``foxglove_bridge`` are its commands (:mod:`~ninjemys.bridge.main`); ``rosapi`` and
``tf2_web_republisher`` are its helper nodes. It stands below the web apps and imports none of
them: the static folder it may serve is an option. See docs/bridge.md and docs/architecture.md.
"""
