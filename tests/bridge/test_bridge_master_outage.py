"""A dead master does not flood the gateway's log: one warning per outage, not one per refresh."""

from __future__ import annotations

import logging
import time

import pytest

from ninjemys.bridge.server import Gateway, GatewayOptions
from ninjemys.master.core import MasterThread
from ninjemys.testing import free_port


def test_graph_refresh_failure_is_logged_once_per_outage(
    monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    master = MasterThread()
    uri = master.__enter__()
    monkeypatch.setenv("ROS_MASTER_URI", uri)
    gateway = Gateway(GatewayOptions(port=free_port(), update_period=0.05))
    gateway.run_in_thread()
    try:
        time.sleep(0.3)
        master.__exit__(None, None, None)
        with caplog.at_level(logging.INFO):
            time.sleep(1.5)  # about 30 refreshes against the dead master
        failures = [r for r in caplog.records if "graph refresh failed" in r.getMessage()]
        assert len(failures) == 1, [r.getMessage() for r in failures]
        assert "retrying every 0.05 s" in failures[0].getMessage()
    finally:
        gateway.shutdown()
