"""The gateway's executables: ``rosbridge_websocket`` (rosbridge_server) and ``foxglove_bridge``.

Both read their settings as ROS 1's do, from private parameters (``_port:=9091`` on the command
line, ``<param>`` in the launch files): ``~port``, ``~address``, ``~ssl``/``~tls``, ``~certfile``,
``~keyfile``, ``~authenticate``, ``~secret_file``, ``~token``, ``~origins``, ``~max_message_size``,
``~send_buffer_limit``, ``~max_update_ms``. Either server also speaks the other protocol on the same
port (a Foxglove client offers its subprotocol, a rosbridge client none).
"""

from __future__ import annotations

import logging
import sys
from typing import Any

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.errors import NinjemysError
from ninjemys.node import Node

log = logging.getLogger(__name__)


def _truthy(value: Any) -> bool:
    if isinstance(value, str):
        return value.strip().lower() in ("1", "true", "yes", "on")
    return bool(value)


def options_from_params(node: Node, default_port: int, node_name: str, client_count: bool) -> GatewayOptions:
    """GatewayOptions from the node's private parameters (ROS 1's names for both bridges)."""

    def param(name: str, default: Any) -> Any:
        value = node.get_param("~" + name, default)
        return default if value == "" and default is not None else value

    origins = param("origins", [])
    if isinstance(origins, str):
        origins = [o.strip() for o in origins.split(",") if o.strip()]
    max_message_size = param("max_message_size", None)
    send_buffer_limit = param("send_buffer_limit", None)
    return GatewayOptions(
        address=str(param("address", "127.0.0.1") or "127.0.0.1"),
        port=int(param("port", default_port)),
        certfile=(param("certfile", None) or None)
        if _truthy(param("ssl", False) or param("tls", False))
        else None,
        keyfile=param("keyfile", None) or None,
        authenticate=_truthy(param("authenticate", False)),
        secret_file=param("secret_file", None)
        or node.get_param("/ros_mac_authentication/secret_file_location", None),
        token=param("token", None) or None,
        origins=list(origins),
        max_message_size=int(max_message_size)
        if max_message_size not in (None, "None")
        else 10 * 1024 * 1024,
        max_client_bytes=int(send_buffer_limit)
        if send_buffer_limit not in (None, "None")
        else 8 * 1024 * 1024,
        update_period=float(param("max_update_ms", 1000)) / 1000.0,
        call_service_timeout=float(param("default_call_service_timeout", 5.0) or 5.0),
        node_name=node_name,
        client_count=client_count,
    )


def _run(default_name: str, default_port: int, argv: list[str] | None, client_count: bool = False) -> int:
    from ninjemys.node.cli_args import parse_args

    args = parse_args([sys.argv[0], *(sys.argv[1:] if argv is None else argv)])
    logging.basicConfig(level=logging.INFO, format="[%(levelname)s] %(message)s")
    name = args.node_name(default_name)
    node = Node(
        name,
        namespace=args.namespace,
        remappings=args.resolved_remappings(args.full_name(name)),
        master_uri=args.master_uri,
        params=args.private_params,
    )
    try:
        options = options_from_params(node, default_port, default_name, client_count)
        gateway = Gateway(options, node=node)
        url = gateway.run_in_thread()
    except (NinjemysError, OSError, ValueError) as exc:
        print(f"{default_name}: {exc}", file=sys.stderr)
        node.shutdown("start-up failed")
        return 1
    log.info("%s: serving rosbridge v2 and Foxglove WebSocket on %s", default_name, url)
    try:
        node.spin()
    except KeyboardInterrupt:
        pass
    finally:
        gateway.shutdown()
        node.shutdown(f"{default_name} exiting")
    return 0


def rosbridge_main(argv: list[str] | None = None) -> int:
    """``rosrun rosbridge_server rosbridge_websocket`` (port 9090)."""
    return _run("rosbridge_websocket", 9090, argv, client_count=True)


def foxglove_main(argv: list[str] | None = None) -> int:
    """``rosrun foxglove_bridge foxglove_bridge`` (port 8765)."""
    return _run("foxglove_bridge", 8765, argv)
