"""Shared helpers of the IDL tests (a uniquely named module: tests/*/conftest.py names collide)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

DATA = Path(__file__).parent / "data"
FIXTURE_SRC = DATA / "ws" / "src"


def populated_all_types() -> Any:
    """An h1_test_msgs/AllTypes with every field set to a non-default value (float32-exact floats)."""
    from ninjemys.idl.loader import get_message_class
    from ninjemys.rostime import Duration, Time

    all_types = get_message_class("h1_test_msgs/AllTypes")
    inner = get_message_class("h1_test_msgs/Inner")
    empty = get_message_class("h1_test_msgs/Empty")
    a = all_types()
    a.header.seq, a.header.stamp, a.header.frame_id = 3, Time(10, 20), "base"
    a.b, a.i8, a.u8, a.by, a.ch = True, -3, 200, -1, 250
    a.i16, a.u16, a.i32, a.u32 = -300, 60000, -70000, 4000000000
    a.i64, a.u64, a.f32, a.f64 = -(2**40), 2**63, 0.5, -2.5
    a.s, a.t, a.d = "héllo", Time(5, 6), Duration(-1, 5)
    a.b_v, a.i8_v, a.u8_v, a.by_v, a.ch_v = [True, False], [-1, 2], b"\x01\x02\xff", [-128, 127], b"ab"
    a.i16_v, a.u16_v, a.i32_v, a.u32_v = [1, -2], [3], [-5], [7, 8]
    a.i64_v, a.u64_v, a.f32_v, a.f64_v = [-9], [10], [0.5, 0.25], [1e300]
    a.s_v, a.t_v, a.d_v = ["x", "", "yz"], [Time(1, 2)], [Duration(-3, 0)]
    a.b_f, a.u8_f, a.ch_f, a.i32_f = [True, True], b"abcd", b"xyz", [1, 2, 3]
    a.f64_f, a.s_f, a.t_f = [float(i) for i in range(36)], ["p", "q"], [Time(1, 1), Time(2, 2)]
    a.inner = inner(kind=1, name="in", values=[1.0, 2.0])
    a.inner.p.x = 3.0
    a.inner_v = [inner(name="a"), inner(name="b", values=[4.0])]
    a.inner_f = [inner(), inner(kind=2)]
    a.empties = [empty(), empty(), empty()]
    return a
