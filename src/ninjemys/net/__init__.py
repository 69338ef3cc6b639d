"""asyncio networking: the XML-RPC server every process serves, and the async XML-RPC client.

The byte-level protocols live in :mod:`ninjemys.wire`; this package only moves bytes over sockets.
"""
