"""Serving browsers: HTTP and WebSocket on asyncio, with no ROS in them.

- :mod:`ninjemys.serve.http`: a small HTTP/1.1 server (routes, static files, JSON, TLS);
- :mod:`ninjemys.serve.websocket`: WebSocket connections on it (``websockets``' sans-I/O protocol),
  with a capped send buffer so a slow reader costs only its own budget.

It sits below the apps (the gateway in :mod:`ninjemys.bridge` and the pages in :mod:`ninjemys.web`
both use it) and apart from :mod:`ninjemys.net`, the node runtime's own loop and XML-RPC, which every
node imports and which has no third-party dependency. See docs/architecture.md.
"""
