"""Every way a service call through the gateway can end answers the client at once, and hung
services neither keep a client waiting past its deadline nor starve calls to other services."""

from __future__ import annotations

import json
import struct
import threading
import time
from collections.abc import Callable, Iterator

import pytest
from websockets.sync.client import ClientConnection, connect

from ninjemys.bridge import graph
from ninjemys.bridge.server import Gateway
from ninjemys.idl.loader import get_service_class
from ninjemys.node import Node

AddTwoInts = get_service_class("rospy_tutorials/AddTwoInts")
_CALL_HEAD = struct.Struct("<BIII")


@pytest.fixture
def release() -> Iterator[threading.Event]:
    """Set at teardown so hung handlers return and their nodes shut down promptly."""
    event = threading.Event()
    yield event
    event.set()


def _recv(ws: ClientConnection, pred: Callable[[object], bool], timeout: float) -> tuple[object, float]:
    """The first message satisfying ``pred`` and how long it took."""
    start = time.monotonic()
    deadline = start + timeout
    while time.monotonic() < deadline:
        try:
            data = ws.recv(timeout=0.1)
        except TimeoutError:
            continue
        item = json.loads(data) if isinstance(data, str) else data
        if pred(item):
            return item, time.monotonic() - start
    raise AssertionError("the expected answer never came")


def _service_ids(ws: ClientConnection, names: set[str]) -> dict[str, int]:
    """The Foxglove service ids of ``names``, from the server's advertiseServices messages."""
    ids: dict[str, int] = {}

    def collect(m: object) -> bool:
        if isinstance(m, dict) and m.get("op") == "advertiseServices":
            ids.update({s["name"]: s["id"] for s in m["services"] if s["name"] in names})
        return set(ids) == names

    _recv(ws, collect, 15.0)
    return ids


def _fox_call(ws: ClientConnection, service_id: int, call_id: int) -> tuple[dict, float]:
    payload = struct.pack("<qq", 2, 3)
    ws.send(_CALL_HEAD.pack(0x02, service_id, call_id, 4) + b"ros1" + payload)

    def answer(m: object) -> bool:
        if isinstance(m, dict):
            return m.get("op") == "serviceCallFailure" and m.get("callId") == call_id
        return isinstance(m, bytes) and m[0] == 0x03 and _CALL_HEAD.unpack_from(m)[2] == call_id

    msg, took = _recv(ws, answer, 8.0)
    if isinstance(msg, bytes):
        return {"op": "response", "payload": msg[_CALL_HEAD.size + 4 :]}, took
    assert isinstance(msg, dict)
    return msg, took


def test_foxglove_every_service_failure_answers_at_once(
    make_gateway: Callable[..., Gateway],
    node: Node,
    master_uri: str,
    release: threading.Event,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    gateway = make_gateway(call_service_timeout=30.0)  # failures must not wait for the deadline

    def boom(_req: object) -> object:
        raise RuntimeError("the handler broke")

    node.service("/fx_boom", AddTwoInts, boom)
    node.service("/fx_ok", AddTwoInts, lambda r: r.a + r.b)
    dying = Node("fx_dying", master_uri=master_uri)
    entered = threading.Event()

    def hang(_req: object) -> object:
        entered.set()
        release.wait(20.0)
        return 0

    dying.service("/fx_dies", AddTwoInts, hang)
    with connect(f"ws://127.0.0.1:{gateway.port}/", subprotocols=["foxglove.websocket.v1"]) as ws:
        ids = _service_ids(ws, {"/fx_boom", "/fx_ok", "/fx_dies"})
        reply, took = _fox_call(ws, ids["/fx_boom"], 1)
        assert reply["op"] == "serviceCallFailure" and "the handler broke" in reply["message"]
        assert took < 5.0
        reply, _ = _fox_call(ws, ids["/fx_ok"], 2)
        assert reply == {"op": "response", "payload": struct.pack("<q", 5)}

        # the provider dies while the call is in its handler
        ws.send(_CALL_HEAD.pack(0x02, ids["/fx_dies"], 3, 4) + b"ros1" + struct.pack("<qq", 1, 1))
        assert entered.wait(10.0)
        threading.Thread(target=dying.shutdown, daemon=True).start()
        msg, took = _recv(ws, lambda m: isinstance(m, dict) and m.get("callId") == 3, 10.0)
        assert isinstance(msg, dict) and msg["op"] == "serviceCallFailure"
        assert took < 10.0

        # a failure the gateway did not foresee (here: the type cannot be loaded) still answers
        def cannot_load(type_name: str, md5sum: str) -> object:
            raise ValueError(f"cannot parse the definition of {type_name}")

        monkeypatch.setattr(graph, "_raw_service_class", cannot_load)
        reply, took = _fox_call(ws, ids["/fx_ok"], 4)
        assert reply["op"] == "serviceCallFailure" and "cannot parse the definition" in reply["message"]
        assert took < 5.0


def test_hung_calls_time_out_and_do_not_starve_other_services(
    make_gateway: Callable[..., Gateway], node: Node, release: threading.Event
) -> None:
    gateway = make_gateway(call_service_timeout=2.0)
    node.service("/rb_hangs", AddTwoInts, lambda r: release.wait(30.0) and 0)
    node.service("/rb_ok", AddTwoInts, lambda r: r.a + r.b)
    url = f"ws://127.0.0.1:{gateway.port}/"
    with connect(url) as hostile, connect(url) as other:
        for i in range(10):
            hostile.send(
                json.dumps(
                    {"op": "call_service", "service": "/rb_hangs", "args": {"a": i, "b": 0}, "id": f"h{i}"}
                )
            )
        time.sleep(0.3)  # the hung calls occupy whatever they can
        other.send(json.dumps({"op": "call_service", "service": "/rb_ok", "args": [20, 22], "id": "ok"}))
        reply, took = _recv(other, lambda m: isinstance(m, dict) and m.get("id") == "ok", 10.0)
        assert isinstance(reply, dict) and reply["result"] is True and reply["values"] == {"sum": 42}
        assert took < 1.5  # well inside the hung calls' deadline: it did not wait behind them
        # the hung ones all get a failed reply at their deadline; a call's own timeout field wins
        hostile.send(
            json.dumps(
                {"op": "call_service", "service": "/rb_hangs", "args": [1, 1], "id": "t", "timeout": 0.5}
            )
        )
        short, took = _recv(hostile, lambda m: isinstance(m, dict) and m.get("id") == "t", 10.0)
        assert isinstance(short, dict) and short["result"] is False and "0.5 s" in short["values"]
        answered = set()
        deadline = time.monotonic() + 10.0
        while len(answered) < 10 and time.monotonic() < deadline:
            msg, _ = _recv(
                hostile, lambda m: isinstance(m, dict) and str(m.get("id", "")).startswith("h"), 10.0
            )
            assert isinstance(msg, dict) and msg["op"] == "service_response" and msg["result"] is False
            assert "did not answer within 2 s" in msg["values"]
            answered.add(msg["id"])
        assert len(answered) == 10
        # and the client is still served
        hostile.send(json.dumps({"op": "call_service", "service": "/rb_ok", "args": [1, 2], "id": "after"}))
        after, _ = _recv(hostile, lambda m: isinstance(m, dict) and m.get("id") == "after", 10.0)
        assert isinstance(after, dict) and after["values"] == {"sum": 3}
