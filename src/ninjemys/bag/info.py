"""``rosbag info`` text, byte for byte in ROS 1's layout (plain and ``-y`` YAML, with ``-k`` keys)."""

from __future__ import annotations

import time
from typing import Any

import yaml

from ninjemys.bag.format import NSEC
from ninjemys.bag.reader import BagReader


def human_size(size: float) -> str:
    """ROS 1's sizes: binary multiples, one decimal, always at least KB."""
    for suffix in ("KB", "MB", "GB", "TB", "PB", "EB", "ZB", "YB"):
        size /= 1024.0
        if size < 1024.0:
            return f"{size:.1f} {suffix}"
    return "-"


def human_frequency(freq: float) -> str:
    for suffix in ("Hz", "kHz", "MHz", "GHz", "THz", "PHz", "EHz", "ZHz", "YHz"):
        if freq < 1000.0:
            return f"{freq:.1f} {suffix}"
        freq /= 1000.0
    return "-"


def _stamp_str(secs: float) -> str:
    frac = ("%.2f" % (secs - int(secs)))[1:]
    return time.strftime("%b %d %Y %H:%M:%S", time.localtime(secs)) + frac


def _median(values: list[float]) -> float:
    ordered = sorted(values)
    n = len(ordered)
    if n % 2:
        return ordered[n // 2]
    return (ordered[n // 2 - 1] + ordered[n // 2]) / 2.0


def topic_frequencies(reader: BagReader) -> dict[str, float]:
    """Median message rate per topic (``rosbag info --freq``); topics with < 2 messages are absent."""
    out: dict[str, float] = {}
    for topic in sorted({c.topic for c in reader.connections.values()}):
        ids = {c.id for c in reader.topic_connections(topic)}
        stamps = [t / NSEC for t in reader.index_times(ids)]
        if len(stamps) > 1:
            period = _median([b - a for a, b in zip(stamps, stamps[1:], strict=False)])
            if period > 0.0:
                out[topic] = 1.0 / period
    return out


def _compression_stats(reader: BagReader) -> tuple[dict[str, int], dict[str, int], dict[str, int]]:
    counts: dict[str, int] = {}
    raw: dict[str, int] = {}
    packed: dict[str, int] = {}
    for header in reader.chunk_headers.values():
        counts[header.compression] = counts.get(header.compression, 0) + 1
        raw[header.compression] = raw.get(header.compression, 0) + header.uncompressed_size
        packed[header.compression] = packed.get(header.compression, 0) + header.compressed_size
    return counts, raw, packed


def _topic_table(reader: BagReader) -> tuple[dict[str, str], dict[str, int], dict[str, int]]:
    datatypes: dict[str, str] = {}
    conn_counts: dict[str, int] = {}
    msg_counts: dict[str, int] = {}
    for topic in sorted({c.topic for c in reader.connections.values()}):
        conns = reader.topic_connections(topic)
        datatypes[topic] = conns[0].datatype
        conn_counts[topic] = len(conns)
        msg_counts[topic] = reader.count(conns)
    return datatypes, conn_counts, msg_counts


def _type_infos(reader: BagReader) -> list[tuple[str, str]]:
    seen: dict[str, str] = {}
    for conn in reader.connections.values():
        seen.setdefault(conn.datatype, conn.md5sum)
    return sorted(seen.items())


def info_text(reader: BagReader, display_path: str, freq: bool = False) -> str:
    """The plain ``rosbag info`` report."""
    rows: list[tuple[str, str]] = [("path", display_path), ("version", reader.version)]
    if not reader.chunk_infos:
        rows.append(("size", human_size(reader.size)))
    else:
        start = reader.chunk_infos[0].start_time / NSEC
        end = reader.chunk_infos[-1].end_time / NSEC
        duration = end - start
        secs = duration % 60
        mins = int(duration / 60)
        hrs = int(mins / 60)
        if hrs > 0:
            dur = "%dhr %d:%02ds (%ds)" % (hrs, mins % 60, secs, duration)
        elif mins > 0:
            dur = "%d:%02ds (%ds)" % (mins, secs, duration)
        else:
            dur = "%.1fs" % duration
        rows.append(("duration", dur))
        rows.append(("start", "%s (%.2f)" % (_stamp_str(start), start)))
        rows.append(("end", "%s (%.2f)" % (_stamp_str(end), end)))
        rows.append(("size", human_size(reader.size)))
        rows.append(("messages", str(reader.message_count)))
        counts, raw, packed = _compression_stats(reader)
        if not counts:
            rows.append(("compression", "none"))
        else:
            total = sum(counts.values())
            parts = []
            for count, kind in sorted(((v, k) for k, v in counts.items()), reverse=True):
                if kind != "none":
                    parts.append(
                        "%s [%d/%d chunks; %.2f%%]" % (kind, count, total, 100.0 * packed[kind] / raw[kind])
                    )
                else:
                    parts.append("%s [%d/%d chunks]" % (kind, count, total))
            rows.append(("compression", ", ".join(parts)))
            if any(k != "none" for k in counts):
                all_raw, all_packed = sum(raw.values()), sum(packed.values())
                raw_s, packed_s = human_size(all_raw), human_size(all_packed)
                width = max(len(raw_s), len(packed_s))
                if duration > 0:
                    raw_r, packed_r = human_size(all_raw / duration), human_size(all_packed / duration)
                    rwidth = max(len(raw_r), len(packed_r))
                    rows.append(("uncompressed", "%*s @ %*s/s" % (width, raw_s, rwidth, raw_r)))
                    rows.append(
                        (
                            "compressed",
                            "%*s @ %*s/s (%.2f%%)"
                            % (width, packed_s, rwidth, packed_r, 100.0 * all_packed / all_raw),
                        )
                    )
                else:
                    rows.append(("uncompressed", "%*s" % (width, raw_s)))
                    rows.append(("compressed", "%*s" % (width, packed_s)))
        types = _type_infos(reader)
        datatypes, conn_counts, msg_counts = _topic_table(reader)
        freqs = topic_frequencies(reader) if freq else {}
        if datatypes:
            tlen = max(len(t) for t in datatypes)
            dlen = max(len(d) for d, _ in types)
            clen = max(len("%d" % n) for n in msg_counts.values())
            flen = max((len(human_frequency(f)) for f in freqs.values()), default=0)
            for i, (datatype, md5) in enumerate(types):
                rows.append(("types" if i == 0 else "", "%-*s [%s]" % (dlen, datatype, md5)))
            for i, topic in enumerate(datatypes):
                n = msg_counts[topic]
                s = "%-*s   %*d %s" % (tlen, topic, clen, n, "msgs" if n > 1 else "msg ")
                if topic in freqs:
                    s += " @ %*s" % (flen, human_frequency(freqs[topic]))
                else:
                    s += "   %*s" % (flen, "")
                s += " : %-*s" % (dlen, datatypes[topic])
                if conn_counts[topic] > 1:
                    s += " (%d connections)" % conn_counts[topic]
                rows.append(("topics" if i == 0 else "", s))
    width = max(len(name) for name, _ in rows) + 1
    text = "".join("%-*s %s\n" % (width, name + ":" if name else "", value) for name, value in rows)
    return text.rstrip()


def info_yaml(reader: BagReader, display_path: str, freq: bool = False) -> str:
    """The ``rosbag info -y`` report (ROS 1's YAML, hand-formatted in its field order)."""
    s = f"path: {display_path}\nversion: {reader.version}\n"
    if not reader.chunk_infos:
        return s + f"size: {reader.size}\nindexed: False\n"
    start = reader.chunk_infos[0].start_time / NSEC
    end = reader.chunk_infos[-1].end_time / NSEC
    s += "duration: %.6f\nstart: %.6f\nend: %.6f\n" % (end - start, start, end)
    s += "size: %d\nmessages: %d\nindexed: True\n" % (reader.size, reader.message_count)
    counts, raw, packed = _compression_stats(reader)
    if not counts:
        s += "compression: none\n"
    else:
        main = sorted(((v, k) for k, v in counts.items()), reverse=True)[0][1]
        s += f"compression: {main}\n"
        if any(k != "none" for k in counts):
            s += "uncompressed: %d\ncompressed: %d\n" % (sum(raw.values()), sum(packed.values()))
    s += "types:\n"
    for datatype, md5 in _type_infos(reader):
        s += f"    - type: {datatype}\n      md5: {md5}\n"
    datatypes, conn_counts, msg_counts = _topic_table(reader)
    freqs = topic_frequencies(reader) if freq else {}
    s += "topics:\n"
    for topic, datatype in datatypes.items():
        s += f"    - topic: {topic}\n      type: {datatype}\n      messages: {msg_counts[topic]}\n"
        if conn_counts[topic] > 1:
            s += f"      connections: {conn_counts[topic]}\n"
        if topic in freqs:
            s += "      frequency: %.4f\n" % freqs[topic]
    return s


class _Obj:
    """Attribute access over a parsed YAML mapping, so ``-k topics[0].type`` works as in ROS 1."""

    def __init__(self, d: dict[str, Any]) -> None:
        for key, value in d.items():
            if isinstance(value, list):
                value = [_Obj(x) if isinstance(x, dict) else x for x in value]
            elif isinstance(value, dict):
                value = _Obj(value)
            setattr(self, key, value)


def _print_yaml(value: Any, indent: int = 0) -> str:
    pad = "  " * indent
    if isinstance(value, list):
        return "".join(f"{pad}- {_print_yaml(item, indent + 1)}\n" for item in value)
    if isinstance(value, _Obj):
        items = list(vars(value).items())
        out = ""
        for i, (k, v) in enumerate(items):
            if i:
                out += pad
            out += f"{k}: {v}"
            if i < len(items) - 1:
                out += "\n"
        return out
    return pad + str(value)


def info_key(yaml_text: str, key: str) -> str | None:
    """The value of ``key`` (``duration``, ``topics``, ``types[0].md5`` ...) or None if absent."""
    obj = _Obj(yaml.safe_load(yaml_text))
    value: Any = obj
    import re

    for part in re.findall(r"[A-Za-z_][A-Za-z0-9_]*|\[\d+\]", key):
        try:
            value = value[int(part[1:-1])] if part.startswith("[") else getattr(value, part)
        except (AttributeError, IndexError, TypeError):
            return None
    return _print_yaml(value)
