"""SHMROS: ninjemys nodes of one host pass large messages through a shared-memory ring (shm_link,
shm_ring). The same stream gives the same bytes as TCPROS and UNIXROS; received arrays are read-only
views that stay valid while held; a slot is never reused while referenced; crashes leave nothing in
/dev/shm; a malformed notice costs one log line and a fall back to TCPROS."""

from __future__ import annotations

import gc
import itertools
import logging
import os
import signal
import subprocess
import sys
import time
from collections import deque
from pathlib import Path

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import shm_link, shm_ring
from ninjemys.testing import NodeProcess, wait_until

pytestmark = pytest.mark.skipif(not shm_ring.available(), reason="SHMROS needs Linux and /dev/shm")

Image = get_message_class("sensor_msgs/Image")
HERE = Path(__file__).parent
BIG = 640 * 480 * 3  # above shm_link.THRESHOLD


@pytest.fixture(autouse=True)
def shm_on(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SHM", "1")
    monkeypatch.delenv(
        "NINJEMYS_UNIXROS", raising=False
    )  # the default: SHMROS streams run on the Unix socket


def _segments(pid: int | None = None) -> list[str]:
    names = [n for n in os.listdir(shm_ring.SHM_DIR) if n.startswith(shm_ring.PREFIX)]
    return names if pid is None else [n for n in names if n.startswith(f"{shm_ring.PREFIX}{pid}-")]


def _transports(node, topic: str) -> list[str]:  # noqa: ANN001
    return [entry[3] for entry in node.bus_info() if entry[4] == topic]


def _image(i: int, size: int) -> Image:
    if size < 70_000:
        data = bytes((i * 7 + k) % 251 for k in range(size))
    else:  # quick to build: first bytes say i, the last byte (i * 3) % 256
        data = bytes([i % 256]) * (size - 1) + bytes([(i * 3) % 256])
    img = Image(height=1, width=size, encoding="mono8", step=size, data=data)
    img.header.seq = i
    return img


def _pub_connection(node, topic: str):  # noqa: ANN001, ANN202
    return node._publications[topic].connections[0]


def test_the_same_stream_is_byte_identical_over_shm_unixros_and_tcpros(make_node, monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_UNIXROS", "1")  # the talker listens on its Unix socket too
    talker = make_node("talker")
    pub = talker.publisher("stream", Image, queue_size=None)
    streams: dict[str, list[bytes]] = {"shm": [], "unix": [], "tcp": []}
    make_node("shm_listener").subscriber(
        "stream", Image, lambda m: streams["shm"].append(bytes(m.data)), raw=True
    )
    assert wait_until(lambda: pub.get_num_connections() == 1)
    monkeypatch.setenv("NINJEMYS_SHM", "0")
    monkeypatch.setenv("NINJEMYS_UNIXROS", "1")
    unix = make_node("unix_listener")
    unix.subscriber("stream", Image, lambda m: streams["unix"].append(bytes(m.data)), raw=True)
    assert wait_until(lambda: pub.get_num_connections() == 2)
    monkeypatch.setenv("NINJEMYS_UNIXROS", "0")
    make_node("tcp_listener").subscriber(
        "stream", Image, lambda m: streams["tcp"].append(bytes(m.data)), raw=True
    )
    assert wait_until(lambda: pub.get_num_connections() == 3)
    assert sorted(_transports(talker, "/stream")) == ["SHMROS", "TCPROS", "UNIXROS"]
    sizes = (0, 1, 1000, shm_link.THRESHOLD - 200, shm_link.THRESHOLD, 300_000, 7, 1920 * 1080 * 3)
    for i, size in enumerate(sizes):
        pub.publish(_image(i, size))
    assert wait_until(lambda: all(len(s) == len(sizes) for s in streams.values()), timeout=20)
    assert streams["shm"] == streams["tcp"] == streams["unix"]
    assert _pub_connection(talker, "/stream").ring._counter == 3  # the three large ones went by the ring


def test_received_arrays_are_read_only_views_that_stay_valid_while_held(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    held: list[Image] = []
    listener.subscriber("img", Image, held.append)
    pub = talker.publisher("img", Image, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    assert _transports(listener, "/img") == ["SHMROS"]
    count = shm_link.SLOTS + 3
    for i in range(count):
        pub.publish(_image(i, BIG))
    assert wait_until(lambda: len(held) == count, timeout=15)
    in_ring = [m for m in held if type(m.data.obj).__name__ == "Lease"]
    # every slot is held by the user: the publisher sent the rest inline rather than overwrite one,
    # and after one wait for a slot it stopped waiting (one stall, not one per message)
    assert len(in_ring) == shm_link.SLOTS
    ring = _pub_connection(talker, "/img").ring
    assert ring._patient is False
    for i, msg in enumerate(held):
        assert msg.header.seq == i + 1 and msg.data[0] == i and msg.data[-1] == (i * 3) % 256
        assert len(msg.data) == BIG
    with pytest.raises(TypeError):
        in_ring[0].data[0] = 1  # read-only
    import numpy as np

    array = np.frombuffer(in_ring[0].data, dtype=np.uint8)
    assert not array.flags.writeable and array[0] == 0
    first = in_ring[0].data[0]
    del held[:], in_ring, msg
    gc.collect()
    # the numpy array still holds slot 0: the next messages take the other slots, never that one
    got: list[Image] = []
    listener.subscriber("img", Image, got.append)
    for i in range(3 * shm_link.SLOTS):
        pub.publish(_image(100 + i, BIG))
        assert wait_until(lambda: got, timeout=10)
        assert got[-1].data[0] == (100 + i) % 256
        got.clear()
        held.clear()
    assert array[0] == first and array[1] == 0 and array[-1] == 0
    assert ring._patient is True  # slots came free: a synchronous publisher waits for them again


def test_queue_size_drops_keep_the_newest_and_free_their_slots(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    seen: list[int] = []

    def slow(msg: Image) -> None:
        seen.append(msg.header.seq)
        time.sleep(0.05)

    listener.subscriber("img", Image, slow, queue_size=1)
    pub = talker.publisher("img", Image, queue_size=1)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    for i in range(1, 61):
        pub.publish(_image(i, BIG))
    assert wait_until(lambda: seen and seen[-1] == 60, timeout=15), seen
    assert len(seen) < 60 and seen == sorted(seen)
    gc.collect()
    ring = _pub_connection(talker, "/img").ring
    assert wait_until(lambda: all(ring._free(s) for s in range(ring.slots)), timeout=5)


def test_a_malformed_notice_is_rejected_with_one_line_and_falls_back_to_tcpros(make_node, caplog) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    got: list[int] = []
    listener.subscriber("img", Image, lambda m: got.append(m.data[0]))
    pub = talker.publisher("img", Image, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(_image(1, BIG))
    assert wait_until(lambda: got == [1])
    ring = _pub_connection(talker, "/img").ring
    good_put = ring.put
    for bad in (
        {"slot": 99},
        {"gen": 12345},
        {"length": shm_link.SLOT_SIZE + 1},
        {"offset": shm_link.SLOT_SIZE},
    ):
        caplog.clear()

        def forged(parts, length, wait=0.0, bad=bad, good_put=good_put):  # noqa: ANN001, ANN202
            frame = good_put(parts, length, wait)
            _, slot, gen, offset, size = shm_ring.NOTICE.unpack_from(frame, 4)
            values = {"slot": slot, "gen": gen, "offset": offset, "length": size, **bad}
            return frame[:4] + shm_ring.NOTICE.pack(
                1, values["slot"], values["gen"], values["offset"], values["length"]
            )

        conn = _pub_connection(talker, "/img")
        conn.ring.put = forged
        with caplog.at_level(logging.WARNING, logger="ninjemys.node.shm_link"):
            pub.publish(_image(2, BIG))
            assert wait_until(lambda: any("malformed" in r.getMessage() for r in caplog.records))
            lines = [r.getMessage() for r in caplog.records if r.name == "ninjemys.node.shm_link"]
            assert len(lines) == 1, lines
            assert (
                "/img" in lines[0]
                and "/talker" in lines[0]
                and next(iter(bad)) in lines[0].replace("generation", "gen")
            )
        # the subscriber reconnects over TCPROS and gets the next messages inline
        assert wait_until(
            lambda sub=listener: _transports(sub, "/img") in (["TCPROS"], ["UNIXROS"]), timeout=10
        )
        assert wait_until(lambda: _transports(talker, "/img") in (["TCPROS"], ["UNIXROS"]), timeout=10)
        got.clear()
        pub.publish(_image(3, BIG))
        assert wait_until(lambda: got == [3])
        # a new subscriber node negotiates SHMROS again, for the next forged notice
        listener.shutdown("next case")
        listener = make_node("listener")
        listener.subscriber("img", Image, lambda m: got.append(m.data[0]))
        assert wait_until(lambda: _transports(talker, "/img") == ["SHMROS"], timeout=10)
        got.clear()
        pub.publish(_image(4, BIG))  # the ring is made with the first large message
        assert wait_until(lambda: got == [4])
        good_put = _pub_connection(talker, "/img").ring.put
    assert not _segments(os.getpid()) or wait_until(lambda: len(_segments(os.getpid())) <= 1)


def test_a_subscriber_killed_mid_stream_leaves_nothing_behind(make_node, master) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("img", Image, queue_size=None)
    before = set(_segments())
    with NodeProcess([sys.executable, str(HERE / "shm_listener_proc.py"), master.uri, "/img"]) as child:
        assert wait_until(lambda: pub.get_num_connections() == 1, timeout=20), child.describe()
        assert _transports(talker, "/img") == ["SHMROS"]
        img = _image(1, BIG)
        deadline = time.monotonic() + 20
        while not any(line.startswith("got 20") for line in child.out) and time.monotonic() < deadline:
            pub.publish(img)
            time.sleep(0.005)
        assert any(line.startswith("got 20") for line in child.out), child.describe()
        os.kill(child.pid, signal.SIGKILL)
        for _ in range(200):  # the stream goes on: the publisher notices, is never stuck
            pub.publish(img)
        assert wait_until(lambda: pub.get_num_connections() == 0, timeout=10)
    assert wait_until(lambda: set(_segments()) <= before, timeout=5), _segments()


def test_a_publisher_killed_mid_write_leaves_nothing_behind(make_node, master) -> None:  # noqa: ANN001
    listener = make_node("listener")
    held: deque[Image] = deque(maxlen=2)  # slots keep coming free: the publisher writes the ring all along
    count = itertools.count(1)
    seen = [0]

    def on_image(msg: Image) -> None:
        held.append(msg)
        seen[0] = next(count)

    listener.subscriber("/image", Image, on_image, queue_size=5)
    child = NodeProcess([sys.executable, str(HERE / "stream_proc.py"), master.uri, "image", "0", "60"])
    try:
        assert wait_until(lambda: seen[0] > 50, timeout=30), child.describe()
        assert _transports(listener, "/image") == ["SHMROS"]
        assert all(type(m.data.obj).__name__ == "Lease" for m in list(held))  # the ring, not inline
        os.kill(child.pid, signal.SIGKILL)
        child.proc.wait()
        assert wait_until(lambda: _transports(listener, "/image") == [], timeout=10)
        assert not _segments(child.pid)
    finally:
        child.kill()
    last = held[-1]
    assert len(last.data) == 640 * 480 * 3 and bytes(last.data[:4]) == b"\0\0\0\0"  # still mapped while held
    # the subscriber is not stuck: a new publisher on the topic reaches it
    pub = make_node("talker2").publisher("/image", Image)
    held.clear()
    assert wait_until(lambda: pub.get_num_connections() == 1, timeout=10)
    pub.publish(_image(5, BIG))
    assert wait_until(lambda: held and held[-1].data[0] == 5, timeout=10)


def test_a_dead_creators_segment_is_reaped_and_ours_are_never_tracked() -> None:
    child = NodeProcess([sys.executable, "-c", "import time; time.sleep(30)"])
    try:
        dead = child.pid
    finally:
        child.kill()
    child.proc.wait()
    stale = Path(shm_ring.SHM_DIR) / f"{shm_ring.PREFIX}{dead}-1-00000000"
    stale.write_bytes(b"x")
    assert stale.name in shm_ring.reap_stale()
    assert not stale.exists()
    # a ring is a plain mapped file: no multiprocessing resource tracker ever learns of it
    ring = shm_ring.WriterRing(2, 1 << 16)
    reader = shm_ring.ReaderRing(ring.name)
    assert not Path(ring.path).exists()  # open-then-unlink
    notice = ring.put([b"abc"], 3)
    assert notice is not None
    view = reader.view(notice[4:])
    assert bytes(view) == b"abc"
    with pytest.raises(shm_ring.ShmError, match="generation"):
        reader.view(notice[4:])  # replayed
    ring.close()
    assert bytes(view) == b"abc"  # the reader's mapping outlives the writer's
    probe = (
        "import sys; from ninjemys.node import shm_ring; r = shm_ring.WriterRing(1, 4096); "
        "shm_ring.ReaderRing(r.name); r.close(); print('multiprocessing' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"  # no resource tracker can unlink a segment behind our back


def test_shmros_is_granted_only_to_this_host_and_named_in_bus_info(make_node, master) -> None:  # noqa: ANN001
    import xmlrpc.client

    talker, listener = make_node("talker"), make_node("listener")
    listener.subscriber("img", Image, lambda m: None)
    pub = talker.publisher("img", Image)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    api = xmlrpc.client.ServerProxy(talker.uri)
    here = shm_link.offer()
    assert here is not None
    code, _, proto = api.requestTopic("/t", "/img", [here, ["TCPROS"]])
    # over the node's Unix socket when it has one (UNIXROS on), else its TCP port
    expected = (
        ["SHMROS", talker.unix_address]
        if talker.unix_address
        else ["SHMROS", talker.tcpros_host, talker.tcpros_port]
    )
    assert code == 1 and proto == expected
    code, _, proto = api.requestTopic("/t", "/img", [["SHMROS", "another-host/1"], ["TCPROS"]])
    assert code == 1 and proto[0] == "TCPROS"
    # what rosnode info shows, from both ends
    info = api.getBusInfo("/t")[2]
    assert [e[3] for e in info if e[4] == "/img"] == ["SHMROS"]
    assert [e[6] for e in info if e[4] == "/img"] == ["SHMROS connection to [/listener]"]
    assert _transports(listener, "/img") == ["SHMROS"]
    # no large message yet: no segment, mapping or descriptor (most topics never need one)
    assert _pub_connection(talker, "/img").ring is None and not _segments(os.getpid())
    rosnode = [str(Path(sys.executable).parent / "rosnode"), "info", "/talker"]
    env = dict(os.environ, ROS_MASTER_URI=master.uri)
    out = subprocess.run(rosnode, env=env, capture_output=True, text=True, timeout=60).stdout
    assert "topic: /img" in out and "transport: SHMROS" in out, out


def test_ninjemys_shm_0_keeps_tcpros(make_node, monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SHM", "0")
    talker, listener = make_node("talker"), make_node("listener")
    got: list[Image] = []
    listener.subscriber("img", Image, got.append)
    pub = talker.publisher("img", Image)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(_image(1, BIG))
    assert wait_until(lambda: got)
    assert (
        _transports(talker, "/img") in (["TCPROS"], ["UNIXROS"]) and type(got[0].data.obj).__name__ != "Lease"
    )


def _mapped(name: str) -> bool:
    return name in Path("/proc/self/maps").read_text()


def test_the_mapping_lives_exactly_as_long_as_a_view_or_the_ring() -> None:
    gc.disable()  # no help from the cycle collector: plain reference counts must free it
    try:
        ring = shm_ring.WriterRing(2, 1 << 16)
        reader = shm_ring.ReaderRing(ring.name)
        notice = ring.put([b"x" * 70_000], 70_000)
        assert notice is None  # beyond the slot: the caller sends it inline
        notice = ring.put([b"hello"], 5)
        assert notice is not None
        view = reader.view(notice[4:])
        tail = view[1:]
        del view
        ring.close()
        del reader
        assert _mapped(ring.name) and bytes(tail) == b"ello"  # the last view keeps it mapped
        del tail
        assert not _mapped(ring.name)  # and its end unmaps it at once
    finally:
        gc.enable()


def test_a_released_slot_is_written_again_and_a_held_one_never() -> None:
    ring = shm_ring.WriterRing(2, 1 << 16)
    reader = shm_ring.ReaderRing(ring.name)
    try:
        first = reader.view(ring.put([b"one"], 3)[4:])  # type: ignore[index]
        second = reader.view(ring.put([b"two"], 3)[4:])  # type: ignore[index]
        assert ring.put([b"three"], 5) is None  # both held
        del second
        third = reader.view(ring.put([b"333"], 3)[4:])  # type: ignore[index]
        assert bytes(first) == b"one" and bytes(third) == b"333"
        # a notice dropped before it was sent (queue_size) gives its slot back
        del third
        dropped = ring.put([b"lost"], 4)
        assert dropped is not None and ring.put([b"x"], 1) is None
        ring.reclaim(dropped)
        assert ring.put([b"y"], 1) is not None
    finally:
        ring.close()
