"""Sans-IO wire protocols: bytes in, bytes out, no sockets and no threads.

``xmlrpc`` (master, parameter server and slave APIs over HTTP/1.1); the TCPROS framing and connection
headers live next to it. The asyncio code that moves these bytes is in :mod:`ninjemys.net`.
"""
