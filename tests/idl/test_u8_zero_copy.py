"""A ``uint8[]`` field given a numpy array goes to the wire without a copy of its own (issue 23: a
camera frame is copied once, into the socket or the shared-memory ring)."""

from __future__ import annotations

import numpy as np

from ninjemys.idl.loader import get_message_class

Image = get_message_class("sensor_msgs/Image")


def _image(data: object) -> object:
    img = Image()
    img.height, img.width, img.encoding, img.step = 4, 6, "rgb8", 18
    img.data = data
    return img


def test_a_contiguous_array_is_framed_as_a_view_of_its_own_memory() -> None:
    rgb = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    total, parts = _image(rgb).frame_parts()
    views = [p for p in parts if isinstance(p, memoryview) and p.nbytes == rgb.nbytes]
    assert views, "the pixels were copied into bytes"
    assert np.shares_memory(np.frombuffer(views[0], dtype=np.uint8), rgb)
    # the same bytes on the wire as from a copy
    assert b"".join(parts) == b"".join(_image(rgb.tobytes()).frame_parts()[1])
    assert total == sum(len(memoryview(p).cast("B")) for p in parts)


def test_arrays_that_are_not_plain_bytes_still_serialize_as_before() -> None:
    rgb = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)
    strided = rgb[:, ::-1]  # not contiguous: copied
    assert _image(strided).serialize_to_bytes() == _image(strided.tobytes()).serialize_to_bytes()
    wide = rgb.astype(np.int16)  # another dtype: converted, as before
    assert _image(wide).serialize_to_bytes() == _image(rgb.tobytes()).serialize_to_bytes()
    flat = rgb.reshape(-1)
    assert _image(flat).serialize_to_bytes() == _image(rgb.tobytes()).serialize_to_bytes()
