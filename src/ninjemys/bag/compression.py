"""Chunk compression: none, bz2 and lz4 (the LZ4 frame format, as ROS 1's roslz4 writes it)."""

from __future__ import annotations

import bz2

import lz4.frame

from ninjemys.errors import BagError


def compress(kind: str, data: bytes) -> bytes:
    if kind == "none":
        return data
    if kind == "bz2":
        return bz2.compress(data, 9)
    if kind == "lz4":
        # what roslz4 accepts: a content checksum, no stored content size, and independent blocks
        # (it cannot follow linked blocks); 64 KiB blocks also let a cut chunk be partly recovered
        return lz4.frame.compress(
            data,
            block_size=lz4.frame.BLOCKSIZE_MAX64KB,
            block_linked=False,
            content_checksum=True,
            store_size=False,
        )
    raise BagError(f"unknown bag compression {kind!r} (expected none, bz2 or lz4)")


def decompress(kind: str, data: bytes | memoryview, size: int, where: str) -> bytes:
    """Decompress a whole chunk; a corrupt or short chunk raises BagError naming ``where``."""
    try:
        if kind == "none":
            out = bytes(data)
        elif kind == "bz2":
            out = bz2.decompress(data)
        elif kind == "lz4":
            out = lz4.frame.decompress(data)
        else:
            raise BagError(f"{where}: unknown chunk compression {kind!r}")
    except (OSError, ValueError, RuntimeError, EOFError) as exc:
        raise BagError(f"{where}: {kind} chunk does not decompress ({exc})") from None
    if len(out) != size:
        raise BagError(f"{where}: chunk decompressed to {len(out)} bytes, header says {size}")
    return out


def decompress_partial(kind: str, data: bytes | memoryview) -> bytes:
    """Decompress as much of a truncated chunk as is intact (crash recovery); never raises."""
    if kind == "none":
        return bytes(data)
    out: list[bytes] = []
    try:
        if kind == "bz2":
            dec = bz2.BZ2Decompressor()
            step = 64 * 1024
            for pos in range(0, len(data), step):
                out.append(dec.decompress(data[pos : pos + step]))
        elif kind == "lz4":
            ldec = lz4.frame.LZ4FrameDecompressor()
            step = 16 * 1024
            for pos in range(0, len(data), step):
                out.append(ldec.decompress(bytes(data[pos : pos + step])))
    except (OSError, ValueError, RuntimeError, EOFError):
        pass
    return b"".join(out)
