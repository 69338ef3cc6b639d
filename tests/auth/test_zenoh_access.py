"""The Zenoh bridge's own links are authenticated with the graph's secret (Zenoh's usrpwd, the password
derived from the secret or the bridge's per-node key): a bridge or a Zenoh peer without it cannot join
the network, so it can neither read nor write a key; one with it can."""

from __future__ import annotations

import queue
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("zenoh", reason="eclipse-zenoh (the zenoh extra) is not installed")

from ninjemys.net import auth  # noqa: E402
from ninjemys.testing import free_port, wait_until  # noqa: E402
from ninjemys.zenoh_bridge import access  # noqa: E402
from ninjemys.zenoh_bridge.core import open_session  # noqa: E402
from ninjemys.zenoh_bridge.options import parse_options  # noqa: E402


class Peer:
    """A bridge's Zenoh session that publishes its name and records what it hears under demo/**."""

    def __init__(self, name: str, argv: list[str], creds: auth.Credentials | None) -> None:
        self.name = name
        options = parse_options(["--no-multicast-scouting", "--ros_name", name, *argv], env={})
        self.session = open_session(options, creds)
        self.heard: queue.Queue[str] = queue.Queue()
        self.sub = self.session.declare_subscriber("demo/**", lambda s: self.heard.put(s.payload.to_string()))

    def say(self) -> None:
        self.session.put(f"demo/{self.name.strip('/')}", self.name)

    def peers(self) -> list[Any]:
        return list(self.session.info.peers_zid())

    def heard_all(self) -> set[str]:
        out = set()
        while not self.heard.empty():
            out.add(self.heard.get_nowait())
        return out

    def close(self) -> None:
        self.session.close()


def _run(hub: Peer, friend: Peer, outsiders: list[Peer]) -> None:
    """The friend joins the hub (both hear each other); the outsiders, given as long again and more,
    have no link, hear nothing and are not heard."""
    started = time.monotonic()
    heard_by_hub: set[str] = set()

    def joined() -> bool:
        for p in (hub, friend, *outsiders):
            p.say()
        heard_by_hub.update(hub.heard_all())
        return friend.name in heard_by_hub and hub.name in friend.heard_all()

    wait_until(joined, timeout=30, what="the bridge with the secret to join", step=0.1)
    settle = time.monotonic() + max(2.0, time.monotonic() - started)
    while time.monotonic() < settle:
        for p in (hub, *outsiders):
            p.say()
        time.sleep(0.1)
    heard_by_hub.update(hub.heard_all())
    for outsider in outsiders:
        assert outsider.peers() == [], f"{outsider.name} joined"
        assert hub.name not in outsider.heard_all(), f"{outsider.name} read the hub's key"
        assert outsider.name not in heard_by_hub, f"{outsider.name} wrote to the hub"


def test_a_bridge_without_the_shared_secret_cannot_join(tmp_path: Path) -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    shared = auth.load_credentials({"NINJEMYS_SECRET": "fleet secret"})
    guess = auth.load_credentials({"NINJEMYS_SECRET": "a guess"})
    peers = [Peer("/hub", ["-l", endpoint], shared)]
    try:
        peers.append(Peer("/friend", ["-e", endpoint], shared))
        peers.append(Peer("/no_secret", ["-e", endpoint], None))
        peers.append(Peer("/wrong_secret", ["-e", endpoint], guess))
        _run(peers[0], peers[1], peers[2:])
    finally:
        for p in peers:
            p.close()


def test_a_secured_bridge_does_not_link_to_an_open_one() -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    shared = auth.load_credentials({"NINJEMYS_SECRET": "fleet secret"})
    peers = [Peer("/open_hub", ["-l", endpoint], None)]
    try:
        peers.append(Peer("/open_friend", ["-e", endpoint], None))
        peers.append(Peer("/secured", ["-e", endpoint], shared))
        _run(peers[0], peers[1], peers[2:])
    finally:
        for p in peers:
            p.close()


def test_per_node_keys_admit_the_bridges_listed_by_name(tmp_path: Path) -> None:
    keys = tmp_path / "keys"
    keys.write_text("/robot1/bridge key-one\n/robot2/bridge key-two\n/robot3/* key-three\n")
    hub_creds = auth.load_credentials({"NINJEMYS_KEYS_FILE": str(keys)})
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    peers = [Peer("/robot1/bridge", ["-l", endpoint], hub_creds)]
    try:
        # robot 2's bridge holds only its own key
        peers.append(
            Peer("/robot2/bridge", ["-e", endpoint], auth.load_credentials({"NINJEMYS_KEY": "key-two"}))
        )
        # robot 1's key claiming robot 2's name; a name covered only by a pattern
        peers.append(
            Peer("/robot2/bridge", ["-e", endpoint], auth.load_credentials({"NINJEMYS_KEY": "key-one"}))
        )
        peers[-1].name = "/robot2/impostor"
        peers.append(
            Peer("/robot3/bridge", ["-e", endpoint], auth.load_credentials({"NINJEMYS_KEY": "key-three"}))
        )
        _run(peers[0], peers[1], peers[2:])
    finally:
        for p in peers:
            p.close()


def test_the_zenoh_password_is_derived_and_the_dictionary_file_is_gone_once_open(tmp_path: Path) -> None:
    shared = auth.load_credentials({"NINJEMYS_SECRET": "fleet secret"})
    assert shared is not None
    with access.usrpwd_settings(shared, "/b") as settings:
        usrpwd: Any = settings["transport/auth/usrpwd"]
        path = Path(usrpwd["dictionary_file"])
        assert path.stat().st_mode & 0o777 == 0o600
        assert "fleet secret" not in path.read_text() and usrpwd["password"] == access.password(
            b"fleet secret"
        )
    assert not path.exists()
    with access.usrpwd_settings(None, "/b") as settings:
        assert settings == {}
    mine = auth.load_credentials({"NINJEMYS_KEYS_FILE": str(_keys(tmp_path))})
    assert mine is not None
    with pytest.raises(access.AccessError, match="no key for the bridge's node /unlisted"):
        access.logins(mine, "/unlisted")


def _keys(tmp_path: Path) -> Path:
    path = tmp_path / "k"
    path.write_text("/listed k\n")
    return path
