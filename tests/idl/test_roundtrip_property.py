"""Property: any valid value of any field kind survives serialize -> deserialize -> serialize unchanged."""

from __future__ import annotations

import struct

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ninjemys.idl.loader import get_message_class, get_message_spec
from ninjemys.idl.spec import FieldType
from ninjemys.rostime import Duration, Time

_INTS = {
    "int8": (-(2**7), 2**7 - 1),
    "byte": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "char": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}


def _float32(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _scalar(base: str) -> st.SearchStrategy:
    if base in _INTS:
        return st.integers(*_INTS[base])
    if base == "bool":
        return st.booleans()
    if base == "float32":
        return st.floats(width=32, allow_nan=False).map(_float32)
    if base == "float64":
        return st.floats(allow_nan=False)
    if base == "string":
        return st.text(max_size=8)
    if base == "time":
        return st.builds(Time, st.integers(0, 2**32 - 1), st.integers(0, 999_999_999))
    if base == "duration":
        return st.builds(Duration, st.integers(-(2**31) + 1, 2**31 - 2), st.integers(0, 999_999_999))
    return message(base)


def _field(ftype: FieldType) -> st.SearchStrategy:
    if not ftype.is_array:
        return _scalar(ftype.base)
    size = (
        {"min_size": ftype.array_len, "max_size": ftype.array_len}
        if ftype.array_len is not None
        else {"max_size": 4}
    )
    if ftype.base in ("uint8", "char"):
        return st.binary(**size)
    return st.lists(_scalar(ftype.base), **size)


def message(type_name: str) -> st.SearchStrategy:
    cls = get_message_class(type_name)
    spec = get_message_spec(type_name)
    return st.builds(cls, **{f.name: _field(f.type) for f in spec.fields})


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.data_too_large,
        HealthCheck.function_scoped_fixture,
    ],
)
@given(data=st.data())
def test_round_trip_preserves_bytes_and_values(fixture_path, data: st.DataObject) -> None:
    for type_name in ("h1_test_msgs/AllTypes", "sensor_msgs/PointCloud2", "rosgraph_msgs/Log"):
        msg = data.draw(message(type_name), label=type_name)
        wire = msg.serialize_to_bytes()
        back = type(msg).deserialize_from(wire)
        assert back == msg
        assert back.serialize_to_bytes() == wire
