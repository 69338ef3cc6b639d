"""Loaned messages (shm_loan): the publisher fills a big array in a shared-memory slot and publish
sends only the notice. A loaned message arrives byte-identical to a plain one over SHMROS and TCPROS;
a loan never published gives its slot back; with every slot busy a loan is a heap array that still
publishes; a publisher killed while holding a loan leaves nothing in /dev/shm."""

from __future__ import annotations

import gc
import os
import signal
import sys
from pathlib import Path

import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.node import shm_link, shm_loan, shm_ring
from ninjemys.testing import NodeProcess, wait_until

pytestmark = pytest.mark.skipif(not shm_ring.available(), reason="SHMROS needs Linux and /dev/shm")

Image = get_message_class("sensor_msgs/Image")
PointCloud2 = get_message_class("sensor_msgs/PointCloud2")
HERE = Path(__file__).parent
W, H = 640, 480
SIZE = W * H * 3


@pytest.fixture(autouse=True)
def shm_on(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setenv("NINJEMYS_SHM", "1")
    monkeypatch.delenv("NINJEMYS_UNIXROS", raising=False)


def _segments(pid: int) -> list[str]:
    return [n for n in os.listdir(shm_ring.SHM_DIR) if n.startswith(f"{shm_ring.PREFIX}{pid}-")]


def _transports(node, topic: str) -> list[str]:  # noqa: ANN001
    return sorted(entry[3] for entry in node.bus_info() if entry[4] == topic)


def _shm_ring(node, topic: str) -> shm_ring.WriterRing:  # noqa: ANN001
    conns = node._publications[topic].connections
    ring = next(c for c in conns if isinstance(c, shm_link.ShmPubConnection)).ring
    assert ring is not None
    return ring


def _pattern(i: int) -> bytes:
    return bytes((i + k) % 256 for k in range(256)) * (SIZE // 256)


def _image_fields(i: int) -> dict:
    return {"height": H, "width": W, "encoding": "rgb8", "step": W * 3, "is_bigendian": i % 2}


def _talker_with_shm_and_tcp_listeners(make_node, monkeypatch, topic: str):  # noqa: ANN001, ANN202
    talker = make_node("talker")
    pub = talker.publisher(topic, Image, queue_size=None)
    got: dict[str, list[bytes]] = {"shm": [], "tcp": []}
    make_node("shm_listener").subscriber(topic, Image, lambda m: got["shm"].append(bytes(m.data)), raw=True)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    monkeypatch.setenv("NINJEMYS_SHM", "0")
    make_node("tcp_listener").subscriber(topic, Image, lambda m: got["tcp"].append(bytes(m.data)), raw=True)
    assert wait_until(lambda: pub.get_num_connections() == 2)
    assert _transports(talker, f"/{topic}") in (["SHMROS", "TCPROS"], ["SHMROS", "UNIXROS"])
    return talker, pub, got


def test_a_loaned_image_arrives_identical_to_a_plain_one_over_shm_and_tcpros(make_node, monkeypatch) -> None:  # noqa: ANN001
    talker, pub, got = _talker_with_shm_and_tcp_listeners(make_node, monkeypatch, "img")
    expected: list[bytes] = []
    plain = Image(**_image_fields(0), data=_pattern(0))
    pub.publish(plain)  # plain: makes the ring
    expected.append(plain.serialize_to_bytes())
    ring = _shm_ring(talker, "/img")
    copied: list[int] = []
    plain_put = ring.put
    ring.put = lambda parts, length, wait=0.0: copied.append(length) or plain_put(parts, length, wait)  # type: ignore[method-assign]
    for i in range(1, 4):
        with pub.loan(SIZE, **_image_fields(i)) as msg:
            assert isinstance(msg, Image)
            msg.header.frame_id = "camera" * i  # fields before the array change its prefix length
            msg.data[:] = memoryview(_pattern(i))
            pub.publish(msg)
            expected.append(msg.serialize_to_bytes())
        assert msg.data == b""  # the end of the block detached the array
    assert wait_until(lambda: len(got["shm"]) == len(got["tcp"]) == 4, timeout=20)
    assert got["shm"] == got["tcp"] == expected
    assert copied == []  # the loaned ones went by their own slot: nothing copied into the ring
    assert ring._counter == 4
    # a field after the array (PointCloud2.is_dense) is written behind it in the slot
    monkeypatch.setenv("NINJEMYS_SHM", "1")
    cloud_pub = talker.publisher("cloud", PointCloud2, queue_size=None)
    clouds: list[bytes] = []
    make_node("cloud_listener").subscriber(
        "cloud", PointCloud2, lambda m: clouds.append(bytes(m.data)), raw=True
    )
    assert wait_until(lambda: cloud_pub.get_num_connections() == 1)
    with cloud_pub.loan(
        1 << 20, height=1, width=1 << 16, point_step=16, row_step=1 << 20, is_dense=True
    ) as c:
        c.data[:] = 5
        cloud_ring = _shm_ring(talker, "/cloud")  # the loan made it
        cloud_ring.put = lambda *args: pytest.fail("copied")  # type: ignore[method-assign]
        cloud_pub.publish(c)
        sent = c.serialize_to_bytes()
    assert wait_until(lambda: clouds == [sent], timeout=10)
    assert sent.endswith(b"\x01") and cloud_ring._counter == 1


def test_a_loan_dropped_unpublished_returns_its_slot(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("img", Image, queue_size=None)
    got: list[Image] = []
    make_node("listener").subscriber("img", Image, got.append)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    gc.disable()  # plain reference counts return the slot, not the cycle collector
    try:
        loan = pub.loan(SIZE, **_image_fields(0))
        ring = _shm_ring(talker, "/img")
        assert loan.shared and ring.lending
        assert sum(ring._free(s) for s in range(ring.slots)) == ring.slots - 1
        msg = loan.msg
        del loan
        del msg  # never published, dropped: the slot is free again
        assert not ring.lending and all(ring._free(s) for s in range(ring.slots))
        with pub.loan(SIZE, **_image_fields(0)) as kept:
            array = kept.data
        assert ring.lending  # the block is over but the user kept the array: still busy
        del array
        assert not ring.lending and all(ring._free(s) for s in range(ring.slots))
    finally:
        gc.enable()
    # the returned slots serve later publishes, loaned or plain
    with pub.loan(SIZE, **_image_fields(1)) as msg:
        msg.data[:] = 3
        pub.publish(msg)
    assert wait_until(lambda: len(got) == 1 and got[0].data[0] == 3 and len(got[0].data) == SIZE)


def test_a_loan_under_all_slots_busy_falls_back_to_the_heap(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("img", Image, queue_size=None)
    got: list[Image] = []
    make_node("listener").subscriber("img", Image, got.append)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    held = [pub.loan(SIZE, **_image_fields(0)) for _ in range(shm_link.SLOTS)]
    assert all(loan.shared for loan in held)
    extra = pub.loan(SIZE, **_image_fields(0))
    assert not extra.shared and extra.msg.data.base is None  # numpy's own heap buffer
    extra.msg.data[:] = 7
    pub.publish(extra.msg)  # an ordinary message: sent inline (every slot is loaned)
    assert wait_until(lambda: len(got) == 1, timeout=10)
    assert bytes(got[0].data) == bytes([7]) * SIZE and type(got[0].data.obj).__name__ != "Lease"
    # the held loans still publish from their slots, each exactly once
    for i, loan in enumerate(held):
        loan.msg.data[:] = i
        pub.publish(loan.msg)
    assert wait_until(lambda: len(got) == 1 + len(held), timeout=10)
    assert [m.data[0] for m in got[1:]] == list(range(len(held)))
    assert all(type(m.data.obj).__name__ == "Lease" for m in got[1:])
    # a small message never takes a slot; no SHMROS subscriber at all: the heap
    assert not pub.loan(100, **_image_fields(0)).shared
    assert not talker.publisher("alone", Image).loan(SIZE).shared


def test_a_loan_names_a_bad_field_or_length(make_node) -> None:  # noqa: ANN001
    pub = make_node("talker").publisher("img", Image)
    with pytest.raises(shm_loan.LoanError, match=r"sensor_msgs/Image.encoding: only a uint8\[\]"):
        pub.loan(10, field="encoding")
    with pytest.raises(shm_loan.LoanError, match="/img: data is the loaned array"):
        pub.loan(10, data=b"x")
    with pytest.raises(shm_loan.LoanError, match="byte count"):
        pub.loan(-1)
    String = get_message_class("std_msgs/String")
    with pytest.raises(
        shm_loan.LoanError, match=r"std_msgs/String: name the field to loan \(uint8\[\] fields: none\)"
    ):
        make_node("other").publisher("s", String).loan(10)


def test_sigkill_while_loaned_leaves_nothing_in_dev_shm(make_node, master) -> None:  # noqa: ANN001
    listener = make_node("listener")
    got: list[Image] = []
    listener.subscriber("/image", Image, got.append)
    child = NodeProcess([sys.executable, str(HERE / "shm_loan_proc.py"), master.uri, "/image"])
    try:
        assert child.wait_for(lambda line: line.startswith("holding"), timeout=30), child.describe()
        assert "holding shared" in child.out
        assert wait_until(lambda: len(got) == 1, timeout=10)
        assert _transports(listener, "/image") == ["SHMROS"]
        assert bytes(got[0].data) == bytes([9]) * SIZE and type(got[0].data.obj).__name__ == "Lease"
        os.kill(child.pid, signal.SIGKILL)
        child.proc.wait()
        assert wait_until(lambda: _transports(listener, "/image") == [], timeout=10)
        assert not _segments(child.pid)
    finally:
        child.kill()
    assert bytes(got[0].data[:3]) == b"\t\t\t"  # still mapped while held


def test_a_subscriber_gone_while_loaned_leaves_the_loan_usable_and_nothing_behind(make_node) -> None:  # noqa: ANN001
    talker, listener = make_node("talker"), make_node("listener")
    pub = talker.publisher("img", Image, queue_size=None)
    listener.subscriber("img", Image, lambda m: None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    loan = pub.loan(SIZE, **_image_fields(0))
    assert loan.shared
    listener.shutdown("gone")
    assert wait_until(lambda: pub.get_num_connections() == 0, timeout=10)
    assert not _segments(os.getpid())
    loan.msg.data[:] = 4  # the mapping lives as long as the loan
    pub.publish(loan.msg)  # nobody to send to: fine
    assert loan.msg.data[0] == 4


def test_an_intraprocess_publisher_leaves_the_shared_loaned_object_whole(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("img", Image, queue_size=None, intraprocess=True)
    inproc: list[Image] = []
    talker.subscriber("img", Image, inproc.append, intraprocess=True)
    remote: list[Image] = []
    make_node("listener").subscriber("img", Image, remote.append)
    assert wait_until(lambda: pub.get_num_connections() == 2)
    with pub.loan(SIZE, **_image_fields(0)) as msg:
        msg.data[:] = 6
        pub.publish(msg)
    assert wait_until(lambda: inproc and remote, timeout=10)
    assert inproc[0] is msg and len(msg.data) == SIZE and msg.data[-1] == 6  # not detached
    assert bytes(remote[0].data) == bytes([6]) * SIZE


def test_a_numpy_image_serializes_without_a_copy_and_with_the_same_bytes() -> None:
    np = pytest.importorskip("numpy")
    pixels = np.arange(H * W * 3, dtype=np.uint8).reshape(H, W, 3)  # as cv_bridge makes them
    img = Image(**_image_fields(0), data=pixels)
    _, parts = img.frame_parts()
    big = [p for p in parts if len(p) == SIZE]
    assert len(big) == 1 and isinstance(big[0], memoryview) and big[0].obj is pixels  # a view, no copy
    assert img.serialize_to_bytes() == Image(**_image_fields(0), data=pixels.tobytes()).serialize_to_bytes()
    strided = pixels[:, ::2]  # not contiguous: copied, as before
    assert Image(data=strided).serialize_to_bytes()[-len(strided.tobytes()) :] == strided.tobytes()
