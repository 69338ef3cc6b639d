"""A raw subscriber alone on its topic (robot_state_publisher's joint states): the worker's solo
rounds deliver its frames inline; what they must keep from the general path is checked here."""

from __future__ import annotations

from node_msgs import String

from ninjemys.testing import wait_until


def _frame(text: str) -> bytes:
    body = len(text).to_bytes(4, "little") + text.encode()
    return len(body).to_bytes(4, "little") + body


def test_raw_alone_in_order_with_header_and_survives_a_raising_callback(make_node) -> None:
    talker, listener = make_node("talker"), make_node("listener")
    got: list[bytes] = []
    headers: list[str] = []

    def callback(raw) -> None:  # noqa: ANN001
        got.append(bytes(raw.data))
        headers.append(raw.connection_header["callerid"])
        if len(got) == 3:
            raise RuntimeError("a callback that raises once")

    listener.subscriber("joints", String, callback, raw=True)
    pub = talker.publisher("joints", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    for i in range(40):
        pub.publish(String(f"m{i}"))
    assert wait_until(lambda: len(got) == 40)
    assert got == [_frame(f"m{i}")[4:] for i in range(40)]
    assert set(headers) == {"/talker"}


def test_raw_alone_then_a_second_callback_and_a_second_handle(make_node) -> None:
    """add_callback and another handle on the topic take the worker off the inline path: every
    callback of every handle still gets every later message."""
    talker, listener = make_node("talker"), make_node("listener")
    first: list[bytes] = []
    second: list[bytes] = []
    other: list[bytes] = []
    sub = listener.subscriber("joints", String, lambda raw: first.append(bytes(raw.data)), raw=True)
    pub = talker.publisher("joints", String, queue_size=None)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    pub.publish(String("alone"))
    assert wait_until(lambda: first == [_frame("alone")[4:]])
    sub.add_callback(lambda raw: second.append(bytes(raw.data)))
    pub.publish(String("two callbacks"))
    assert wait_until(lambda: len(first) == 2 and second == [_frame("two callbacks")[4:]])
    listener.subscriber("joints", String, lambda raw: other.append(bytes(raw.data)), raw=True)
    # the second handle shares the stream once its worker has it: publish until it hears one
    wait_until(lambda: pub.publish(String("shared")) or other, step=0.1)
    assert set(other) == {_frame("shared")[4:]}
    assert first[-1] == second[-1] == _frame("shared")[4:]


def test_publish_framed_to_one_socket_subscriber(make_node) -> None:
    """publish_framed's one-subscriber path (not latched): the frame as built, in order."""
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    listener.subscriber("framed", String, lambda m: got.append(m.data))
    pub = talker.publisher("framed", String, queue_size=10)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    for i in range(20):
        pub.publish_framed(_frame(f"f{i}"))
    assert wait_until(lambda: len(got) == 20)
    assert got == [f"f{i}" for i in range(20)]
