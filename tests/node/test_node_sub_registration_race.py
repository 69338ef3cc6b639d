"""A new subscriber whose registerSubscriber answer (no publishers yet) is overtaken by the master's
publisherUpdate (the publisher registered meanwhile) still connects: the older answer must not undo
the newer update (turtlesim's test saw a fresh /turtle1/pose subscriber get nothing for 10 s)."""

from __future__ import annotations

import time

from node_msgs import String

from ninjemys.testing import wait_until


def test_a_stale_registration_answer_does_not_undo_a_newer_publisher_update(make_node) -> None:  # noqa: ANN001
    talker = make_node("talker")
    pub = talker.publisher("chatter", String)
    listener = make_node("listener")
    real = listener.registrar.add_subscriber

    def answer_then_overtaken(topic: str, type_name: str, *place: object) -> list[str] | None:
        real(topic, type_name, *place)  # type: ignore[arg-type]  # registered now; the master would answer [talker]
        # the interleaving of the race, made certain: the master answered before the publisher was
        # registered, and its publisherUpdate reached the node's loop before that answer was applied
        listener.publisher_update(topic, [talker.uri])
        listener.runtime.run(_noop())  # the loop has applied the update
        return []

    listener.registrar.add_subscriber = answer_then_overtaken  # type: ignore[method-assign]
    got: list[str] = []
    sub = listener.subscriber("chatter", String, lambda m: got.append(m.data))
    listener.runtime.run(_noop())  # whatever subscriber() handed the loop has been applied
    assert sub._sub.publishers == [talker.uri]  # the answer did not take back the newer list
    assert wait_until(lambda: sub.publisher_ids() == {talker.name}, timeout=10)
    time.sleep(0.3)
    assert sub.publisher_ids() == {talker.name} and pub.get_num_connections() == 1
    pub.publish(String(data="hello"))
    assert wait_until(lambda: got == ["hello"], timeout=10)


async def _noop() -> None:
    return None
