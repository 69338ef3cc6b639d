"""Raw (Foxglove) service calls to one service, again and again, on the gateway's persistent proxy."""

from __future__ import annotations

from ninjemys.bridge.graph import Services
from ninjemys.idl.loader import get_service_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node


def test_raw_calls_to_one_service_all_answer() -> None:
    with MasterThread() as uri:
        server = Node("raw_repeat_server", master_uri=uri)
        client = Node("raw_repeat_client", master_uri=uri)
        try:
            services = Services(client)
            response_class = get_service_class("roscpp/GetLoggers")._response_class
            for _ in range(3):
                raw = services.call_raw("/raw_repeat_server/get_loggers", b"")
                names = [logger.name for logger in response_class.deserialize_from(raw).loggers]
                assert names
            services.close()
        finally:
            client.shutdown("test over")
            server.shutdown("test over")
