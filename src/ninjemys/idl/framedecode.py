"""The fused receive loop: one generated function per message type that cuts TCPROS frames out of a
received chunk and decodes each in place, in one Python function.

Why: for a small message the generic path spends as much as the decode itself on cutting the frame
(one ``unpack_from`` and one ``bytes`` copy per frame, a list append) and on calling
``deserialize_from`` (a call, a buffer check, a ``try`` set-up). Here a chunk of many frames costs one
call; per frame there is one ``unpack_from`` of its length and the type's straight-line decode,
reading the chunk at offsets.

The function is generated on first use (most classes are never subscribed to, and node start-up
compiles every class it loads), from the same emitter as ``deserialize_from``, so both decode the same
bytes to the same values. Signature of the generated function::

    decode_frames(data: bytes, pos: int, stop: int, out: list, bad: list) -> int

It decodes the complete frames of ``data[pos:stop]`` into ``out`` and returns the offset of the first
incomplete one; a frame that does not decode adds ``(its length, DeserializationError)`` to ``bad`` and is skipped
(its length prefix says where the next one starts). ``data`` must be immutable ``bytes``: array fields
are views into it, which keep it alive as long as the message lives.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from ninjemys.idl.codegen import _DeserEmitter, min_size
from ninjemys.idl.message import DeserializationError

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

#: the generated function (see the module docstring)
FramesDecoder = Callable[[bytes, int, int, list, list], int]

_lock = threading.Lock()
_decoders: dict[tuple[type, bool], tuple[FramesDecoder, int] | None] = {}


class _FrameDeserEmitter(_DeserEmitter):
    """The class's decode, bounded by its frame: ``deserialize_from`` gets a buffer that ends where
    the message ends, so a fixed-size run past it is a ``struct.error``; here the chunk goes on with
    the next frame, so every fixed-size read is followed by a check against the frame's end (one
    comparison per run)."""

    _after_unpack = False  # the last line read a fixed-size run
    _check = ""  # the check owed by the last run, emitted before whatever comes next

    def emit(self, line: str) -> None:
        if self._check:
            # a length prefix read in the run is checked against the frame's end next anyway
            # (``end - pos`` is then negative): only a run that no such check follows needs its own
            if ": raise _short(" not in line:
                super().emit(self._check)
            self._check = ""
        super().emit(line)
        if line.startswith("pos += ") and self._after_unpack:
            self._check = "if pos > end: raise _overrun(end - pos)"
        self._after_unpack = ".unpack_from(mv, pos)" in line

    def finish(self) -> None:
        """Emit the check the last run owes."""
        if self._check:
            super().emit(self._check)
            self._check = ""


def _overrun(short: int) -> ValueError:
    """The error of a frame that ends inside a fixed-size field (``deserialize_from`` wraps it)."""
    return ValueError(f"the frame ends {-short} bytes before its fixed-size fields do")


def frames_decoder_source(spec: Any, lookup: Callable[[str], Any], tagged: bool = False) -> str:
    """Python source of ``decode_frames`` for ``spec`` (a pure function of its inputs). ``tagged``: for
    a stream whose bodies start with a tag byte (SHMROS): a frame tagged 0 is decoded after its tag,
    and the first frame with another tag ends the run (the caller's generic path takes it)."""
    structs: dict[str, str] = {}
    de = _FrameDeserEmitter(spec.full_name, lookup, structs, depth=3)
    de.fields(spec, "o")
    de.flush()
    de.finish()
    if not de.views:  # strings and numbers only: slice and decode the bytes directly
        structs.clear()
        de = _FrameDeserEmitter(spec.full_name, lookup, structs, depth=3, bytes_buffer=True)
        de.fields(spec, "o")
        de.flush()
        de.finish()
    head = [f"{name} = _struct.Struct({fmt!r})" for fmt, name in structs.items()]
    # where a failed frame's body starts (``pos`` has moved into it): after its length and its tag
    body_start = "end - _fl + 1" if tagged else "end - _fl"
    body = [
        "_FL = _struct.Struct('<I').unpack_from",
        "",
        "def decode_frames(data, pos, stop, out, bad):",
        "    cls = _cls",
        "    append = out.append",
        *(["    mv = memoryview(data)", "    sb = data"] if de.views else ["    mv = data"]),
        "    while stop - pos >= 4:",
        "        (_fl,) = _FL(data, pos)",
        "        end = pos + 4 + _fl",
        "        if end > stop:",
        "            break",
        *(
            ["        if not _fl or data[pos + 4]:", "            break", "        pos += 5"]
            if tagged
            else ["        pos += 4"]
        ),
        "        try:",
        "            o = _new(cls)",
        *de.lines,
        "            append(o)",
        "        except _DeserializationError as exc:",
        f"            bad.append((end - ({body_start}), exc))",
        "        except _DESER_ERRORS as exc:",
        f"            bad.append((end - ({body_start}), _deser_failed(cls, data[{body_start}:end], exc)))",
        "        pos = end",
        "    return pos",
    ]
    return "\n".join(head + body) + "\n"


def frames_decoder(cls: Any, tagged: bool = False) -> tuple[FramesDecoder, int] | None:
    """``(decode_frames, smallest frame in bytes)`` for a generated message class and a stream with or
    without tags, made once; None for a class not generated by our loader (the caller keeps the
    per-frame path)."""
    key = (cls, tagged)
    try:
        return _decoders[key]
    except KeyError:
        pass
    with _lock:
        if key not in _decoders:
            _decoders[key] = _make(cls, tagged)
        return _decoders[key]


def _make(cls: Any, tagged: bool) -> tuple[FramesDecoder, int] | None:
    made = getattr(cls, "_spec_lookup", None)
    deser = getattr(cls, "deserialize_from", None)
    if made is None or deser is None:
        return None
    from ninjemys.idl.codecache import compile_cached

    spec, lookup = made
    generated = deser.__func__.__globals__  # the class's own runtime names and nested classes
    own = generated.get(spec.short_name)
    if own is None or deser.__func__ is not own.__dict__.get("deserialize_from").__func__:
        return None  # a subclass that decodes its own way: the fused loop would bypass it
    namespace = dict(generated)
    namespace["_cls"] = cls
    namespace["_DeserializationError"] = DeserializationError
    namespace["_overrun"] = _overrun
    source = frames_decoder_source(spec, lookup, tagged)
    exec(compile_cached(source, f"<ninjemys frames decoder {spec.full_name}>"), namespace)  # noqa: S102
    return namespace["decode_frames"], (5 if tagged else 4) + min_size(spec, lookup)
