"""The command's other options: a Zenoh configuration file under the command line, and a master
started inside the bridge."""

from __future__ import annotations

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.master.client import MasterClient  # noqa: E402
from ninjemys.testing import free_port, wait_until  # noqa: E402
from ninjemys.zenoh_bridge.core import open_session  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402

from .bridges import start_bridge  # noqa: E402


def test_config_file_then_command_line(tmp_path):
    port = free_port()
    conf = tmp_path / "zenoh.json5"
    conf.write_text(f'{{ mode: "peer", listen: {{ endpoints: ["tcp/127.0.0.1:{port}"] }} }}\n')
    session = open_session(parse_options(["-c", str(conf), "--no-multicast-scouting"], env={}))
    try:
        other = open_session(
            parse_options(["-e", f"tcp/127.0.0.1:{port}", "--no-multicast-scouting"], env={})
        )
        try:  # the listener came from the file: the other session reaches it
            wait_until(lambda: str(session.zid()) in {str(z) for z in other.info.peers_zid()}, timeout=20,
                       what="the sessions to connect")  # fmt: skip
        finally:
            other.close()
    finally:
        session.close()


def test_with_rosmaster_starts_a_master():
    uri = f"http://localhost:{free_port()}/"
    with start_bridge(uri, "--with_rosmaster", "true", "-l", f"tcp/127.0.0.1:{free_port()}") as bridge:
        with MasterClient(uri, "/test_probe") as m:
            assert m.get_pid() == bridge.pid
        bridge.wait_for("reached", timeout=20)
