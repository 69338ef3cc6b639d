"""rqt_bag's playback reaches the subscribers that were there when it started, from the first message,
however fast it plays: it waits for them to connect to the publishers it has just advertised."""

from __future__ import annotations

from pathlib import Path

from ninjemys.bag.api import Bag
from ninjemys.idl.loader import get_message_class
from ninjemys.master.core import MasterThread
from ninjemys.node import Node
from ninjemys.rostime import Time
from ninjemys.testing import wait_until
from ninjemys.web.rqt import BagSession

Float64 = get_message_class("std_msgs/Float64")


def test_a_fast_playback_reaches_a_waiting_subscriber_from_the_first_message(tmp_path: Path) -> None:
    path = tmp_path / "run.bag"
    with Bag(str(path), "w") as bag:
        for i in range(20):
            bag.write("/odom_x", Float64(data=float(i)), Time(100 + i // 2, (i % 2) * 500_000_000))
    with MasterThread() as uri:
        player = Node("rqt_bag_player", anonymous=True, master_uri=uri)
        listener = Node("bag_listener", anonymous=True, master_uri=uri)
        session = BagSession(player, [str(path)])
        try:
            received: list[float] = []
            listener.subscriber("/odom_x", Float64, lambda m: received.append(m.data), queue_size=100)
            session.play(None, 1000.0, True)  # the whole bag in 10 ms
            wait_until(lambda: len(received) == 20, what="the 20 played messages")
            assert received == [float(i) for i in range(20)]
        finally:
            session.close()
            listener.shutdown("test over")
            player.shutdown("test over")
