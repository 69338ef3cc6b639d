"""Networking on an event loop: the XML-RPC server every process serves, the async XML-RPC client, and
the small coroutine loop (:mod:`ninjemys.net.loop`) that node processes use instead of asyncio.

The byte-level protocols live in :mod:`ninjemys.wire`; this package only moves bytes over sockets.
"""
