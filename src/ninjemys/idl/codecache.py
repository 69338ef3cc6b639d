"""An on-disk cache of compiled generated classes, so a node's start-up skips ``compile()``.

Compiling the generated source is most of the cost of a message class (parsing, md5 and code
generation together take a fraction of it). The compiled code object is stored with ``marshal`` under
``$ROS_HOME/ninjemys/codecache/`` (``~/.ros`` when ROS_HOME is unset), keyed by a hash of the source and
the interpreter's cache tag, so any change of definition, generator or Python version is a new entry
and stale entries are never used. Writes are atomic (temp file + rename); a cache that cannot be read
or written is skipped silently, never an error. ``NINJEMYS_CODE_CACHE=0`` disables it.
"""

from __future__ import annotations

import marshal
import os
import sys
from types import CodeType


def cache_dir() -> str | None:
    """The cache directory, or None when disabled."""
    if os.environ.get("NINJEMYS_CODE_CACHE", "1") == "0" or sys.implementation.cache_tag is None:
        return None
    home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return os.path.join(home, "ninjemys", "codecache")


def compile_cached(source: str, filename: str) -> CodeType:
    """``compile(source, filename, "exec")``, reusing an earlier compilation of the same source."""
    folder = cache_dir()
    if folder is None:
        return compile(source, filename, "exec")
    import hashlib  # here, not at module level: ~4 ms of start-up for processes that never compile

    key = hashlib.sha256(f"{filename}\0{source}".encode()).hexdigest()[:40]
    path = os.path.join(folder, f"{key}.{sys.implementation.cache_tag}.code")
    try:
        with open(path, "rb") as f:
            code = marshal.loads(f.read())
        if isinstance(code, CodeType):
            return code
    except (OSError, ValueError, EOFError, TypeError):
        pass
    code = compile(source, filename, "exec")
    tmp = f"{path}.{os.getpid()}.tmp"
    try:
        os.makedirs(folder, exist_ok=True)
        with open(tmp, "wb") as f:
            f.write(marshal.dumps(code))
        os.replace(tmp, path)
    except OSError:
        try:
            os.unlink(tmp)
        except OSError:
            pass
    return code
