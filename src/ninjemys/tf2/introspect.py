"""What the buffer core says about itself: frame lists and tf2's text, YAML and Graphviz views (what
``tf_echo``, ``tf2_monitor`` and ``view_frames`` read).
"""

from __future__ import annotations

from ninjemys.tf2.ingest import Ingest
from ninjemys.tf2.storage import Frame, _secs


class Introspection(Ingest):
    """Frame names and the text views (each drains the raw queue first)."""

    def frame_exists(self, name: str) -> bool:
        """tf2's ``_frameExists``: the name is known (as a child or as a parent)."""
        self._pull()
        with self._lock:
            self._drain()
            return name in self._frames

    def child_frames(self) -> list[str]:
        """The frames that have a parent now (the keys of :meth:`all_frames_as_yaml`), in tf2's order."""
        self._pull()
        with self._lock:
            self._drain()
            return [f.name for f in self._order if f.has_cache and f.data]

    def frame_names(self) -> list[str]:
        """Every known frame, in the order tf2 numbered them (``_getFrameStrings``)."""
        self._pull()
        with self._lock:
            self._drain()
            return [f.name for f in self._order]

    def all_frames_as_string(self) -> str:
        """tf2's ``allFramesAsString``: one "Frame x exists with parent y." line per child frame."""
        self._pull()
        with self._lock:
            self._drain()
            return self._frames_as_string()

    def _stats(self, f: Frame) -> tuple[str, float, float, float, float]:
        """(parent name, rate, newest, oldest, buffer length) of a frame with data, as tf2 computes them."""
        latest = _secs(f.latest)
        oldest = _secs(f.oldest())
        rate = len(f.data) / max(latest - oldest, 0.0001)
        return f.data[-1][0].name, rate, latest, oldest, _secs(f.latest - f.oldest())

    def all_frames_as_yaml(self, current_time: float = 0.0) -> str:
        """tf2's ``allFramesAsYAML`` (what ``tf2_frames`` and view_frames read)."""
        self._pull()
        with self._lock:
            self._drain()
            out = [] if self._order else ["{}"]
            for f in self._order:
                if not f.has_cache or not f.data:
                    continue
                parent, rate, latest, oldest, length = self._stats(f)
                out.append(
                    f"{f.name}: \n  parent: '{parent}'\n  broadcaster: '{f.authority or 'no recorded authority'}'\n"
                    f"  rate: {rate:.3f}\n  most_recent_transform: {latest:.3f}\n  oldest_transform: {oldest:.3f}\n"
                )
                if current_time > 0:
                    out.append(f"  transform_delay: {current_time - latest:.3f}\n")
                out.append(f"  buffer_length: {length:.3f}\n")
            return "".join(out)

    def all_frames_as_dot(self, current_time: float = 0.0) -> str:
        """tf2's ``_allFramesAsDot``: the frame tree for Graphviz, with tf2's labels."""
        self._pull()
        with self._lock:
            self._drain()
            out = ["digraph G {\n"]
            if not self._order:
                out.append('"no tf data recieved"')
            for f in self._order:
                if not f.has_cache or not f.data:
                    continue
                parent, rate, latest, _, length = self._stats(f)
                age = f"( {current_time - latest:.3f} sec old)" if current_time > 0 else ""
                out.append(
                    f'"{parent}" -> "{f.name}"[label="Broadcaster: {f.authority or "no recorded authority"}\\n'
                    f"Average rate: {rate:.3f} Hz\\nMost recent transform: {latest:.3f} {age}\\n"
                    f'Buffer length: {length:.3f} sec\\n"];\n'
                )
            legend = ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";\n'
            for f in self._order:
                if not f.has_cache:
                    if current_time > 0:
                        out.append(
                            f'edge [style=invis];\n{legend}"Recorded at time: {current_time:.3f}"[ shape=plaintext ] ;\n'
                            f' }}->"{f.name}";\n'
                        )
                    continue
                if not f.data:
                    out.append("edge [style=invis];\n" + legend)
                    if current_time > 0:
                        out.append(f'"Recorded at time: {current_time:.3f}"[ shape=plaintext ] ;\n ')
                    out.append(f'}}->"{f.name}";\n')
            out.append("}")
            return "".join(out)
