"""``rosrun rosserial_python serial_node.py``: a rosserial device on a serial port or over TCP.

Serial (the default)::

    rosrun rosserial_python serial_node.py _port:=/dev/ttyACM0 _baud:=57600
    rosrun rosserial_python serial_node.py /dev/ttyUSB0            # the port as an argument, as in ROS 1

``~port`` (/dev/ttyUSB0), ``~baud`` (57600), ``~fix_pyserial_for_test`` (accepted and not needed: it
worked around pyserial 2's ``inWaiting`` on ptys; this host reads with a timeout instead),
``~sync_timeout`` (ninjemys: seconds without time sync before "Lost sync with device, restarting...";
rosserial_python's fixed 15 s by default). A port that cannot be opened, or that goes away (a board
unplugged), is retried every second with one error line, as the board may come back.

TCP, for ESP32-class boards (rosserial's ``ros_lib`` with ``ROSSERIAL_ARDUINO_TCP``)::

    rosrun rosserial_python serial_node.py tcp [11411]

``~tcp_port`` (else ``/rosserial_embeddedlinux/tcp_port``, else 11411) when no port argument is given; each connection is served in turn (``~fork_server``
is accepted; one device at a time, as without it in ROS 1). ``rosrun rosserial_server serial_node`` and
``socket_node`` are the same host under rosserial_server's names (``rosserial_server_serial_node`` with
``~port`` /dev/ttyACM0, ``rosserial_server_socket_node`` with ``~port`` 11411); ``rosserial_arduino
serial_node.py`` is rosserial_python's; ``message_info_service.py`` only says it is no longer needed.
"""

from __future__ import annotations

import socket
import sys
from typing import Any

from ninjemys.drivers.rosserial_host import SYNC_TIMEOUT, RosserialHost
from ninjemys.node.run import run_node

DEFAULT_TCP_PORT = 11411
#: seconds between opening a serial port and asking the board for its topics (rosserial_python's)
BOOT_WAIT = 2.1


class SocketLink:
    """A TCP connection with the serial link's interface (reads time out and return b"")."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        sock.settimeout(0.1)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def read(self, size: int) -> bytes:
        try:
            data = self.sock.recv(max(size, 4096))
        except TimeoutError:
            return b""
        if not data:
            raise ConnectionResetError("the device closed the connection")
        return data

    def write(self, data: bytes) -> None:
        self.sock.sendall(data)

    def close(self) -> None:
        self.sock.close()


def open_serial(port: str, baud: int) -> Any:
    """pyserial's port in raw mode, reads timing out after 0.1 s so shutdown is seen promptly."""
    import serial  # type: ignore[import-untyped]  # pyserial: imported here so that `import ninjemys.drivers` costs nothing

    return serial.Serial(port, baud, timeout=0.1, write_timeout=5.0)


def _positional(argv: list[str]) -> list[str]:
    return [a for a in argv if ":=" not in a and not a.startswith("__")]


def _serve(node: Any, host: RosserialHost) -> None:
    try:
        host.run()
    except OSError as exc:
        if not node.is_shutdown:
            node.log.error("rosserial: the link failed: %s", exc)
    finally:
        host.close()
        try:
            host.link.close()
        except OSError:
            pass


def serve_serial(node: Any, port: str, baud: int, sync_timeout: float) -> None:
    first_error = True
    while not node.is_shutdown:
        node.log.info("Connecting to %s at %d baud", port, baud)
        try:
            link = open_serial(port, baud)
        except (OSError, ValueError) as exc:  # serial.SerialException is an OSError
            if first_error:
                node.log.error("Error opening serial: %s", exc)
                first_error = False
            node.wait_for_shutdown(1.0)
            continue
        first_error = True
        # opening the port pulses DTR, which resets an Arduino: its bootloader would swallow the topic
        # request, and the sketch waits for one, so wait as rosserial_python does (0.1 + 2 s), then drop
        # what the bootloader printed
        node.wait_for_shutdown(BOOT_WAIT)
        try:
            link.reset_input_buffer()
        except (OSError, AttributeError):
            pass
        _serve(node, RosserialHost(node, link, sync_timeout))
        if not node.is_shutdown:
            node.wait_for_shutdown(1.0)


def serve_tcp(node: Any, port: int, sync_timeout: float) -> None:
    server = socket.create_server(("", port), reuse_port=False)
    server.settimeout(0.2)
    node.on_shutdown(server.close)
    node.log.info("Fork_server is: %s", bool(node.get_param("~fork_server", False)))
    node.log.info("Waiting for socket connections on port %d", port)
    node.log.info("Waiting for socket connection")
    try:
        while not node.is_shutdown:
            while not node.is_shutdown:
                try:
                    sock, addr = server.accept()
                    break
                except TimeoutError:
                    continue
                except OSError:
                    return  # closed by shutdown
            else:
                return
            node.log.info("Established a socket connection from %s on port %s", addr[0], addr[1])
            node.log.info("calling startSerialClient")
            _serve(node, RosserialHost(node, SocketLink(sock), sync_timeout))
            node.log.info("Client has exited, closing socket.")
            node.log.info("startSerialClient() exited")
    finally:
        server.close()


def _tcp_port_param(node: Any) -> int:
    """``~tcp_port``, else the global ``/rosserial_embeddedlinux/tcp_port`` that rosserial_python still
    reads for older launch files, else 11411."""
    if node.has_param("~tcp_port"):
        return int(node.get_param("~tcp_port"))
    return int(node.get_param("/rosserial_embeddedlinux/tcp_port", DEFAULT_TCP_PORT))


def main(argv: list[str] | None = None) -> int:
    """``rosrun rosserial_python serial_node.py [port | tcp [tcp_port]]``."""
    args = sys.argv[1:] if argv is None else list(argv)
    positional = _positional(args)

    def build(node: Any) -> int:
        node.log.info("ROS Serial Python Node")
        sync_timeout = float(node.get_param("~sync_timeout", SYNC_TIMEOUT))
        # as rosserial_python: the first argument (else ~port) names the port, and "tcp" there, from
        # either, means the TCP server, on the second argument (else ~tcp_port)
        port = positional[0] if positional else str(node.get_param("~port", "/dev/ttyUSB0"))
        if port == "tcp":
            try:
                tcp_port = int(positional[1]) if len(positional) > 1 else _tcp_port_param(node)
            except ValueError:
                node.log.fatal("serial_node.py tcp: the port must be a number, got %s", positional[1])
                return 2
            serve_tcp(node, tcp_port, sync_timeout)
            return 0
        baud = int(node.get_param("~baud", 57600))
        node.get_param("~fix_pyserial_for_test", False)
        serve_serial(node, port, baud, sync_timeout)
        return 0

    return run_node("serial_node", args, build)


def server_serial_main(argv: list[str] | None = None) -> int:
    """``rosrun rosserial_server serial_node``: the serial host under rosserial_server's node name
    (``rosserial_server_serial_node``) and defaults (``~port`` /dev/ttyACM0, ``~baud`` 57600); the
    port is a parameter only, as in rosserial_server."""
    args = sys.argv[1:] if argv is None else list(argv)

    def build(node: Any) -> int:
        serve_serial(
            node,
            str(node.get_param("~port", "/dev/ttyACM0")),
            int(node.get_param("~baud", 57600)),
            float(node.get_param("~sync_timeout", SYNC_TIMEOUT)),
        )
        return 0

    return run_node("rosserial_server_serial_node", args, build)


def socket_main(argv: list[str] | None = None) -> int:
    """``rosrun rosserial_server socket_node``: the TCP host on ``~port`` (11411), node name
    ``rosserial_server_socket_node`` as in rosserial_server."""
    args = sys.argv[1:] if argv is None else list(argv)

    def build(node: Any) -> int:
        serve_tcp(
            node,
            int(node.get_param("~port", DEFAULT_TCP_PORT)),
            float(node.get_param("~sync_timeout", SYNC_TIMEOUT)),
        )
        return 0

    return run_node("rosserial_server_socket_node", args, build)


def arduino_main(argv: list[str] | None = None) -> int:
    """``rosrun rosserial_arduino serial_node.py``: rosserial_arduino's copy of the serial host (older
    tutorials start it under this package). ``~auto_reset_timeout`` is accepted; the board is not reset
    through DTR, the host asks it for its topics again as after any lost sync."""
    return main(argv)


def message_info_main(argv: list[str] | None = None) -> int:
    """``rosrun rosserial_python message_info_service.py``: kept, as in rosserial, so launch files that
    start it beside rosserial_server still work; it only says it is no longer needed."""
    args = sys.argv[1:] if argv is None else list(argv)

    def build(node: Any) -> int:
        node.log.warn(
            "The message info service node is no longer needed and will be removed in a future "
            "release of rosserial."
        )
        return 0

    return run_node("message_info_service", args, build)
