"""The rosout node: subscribes /rosout, republishes every message on /rosout_agg, writes rosout.log.

It is an ordinary node of the ninjemys runtime (``ninjemys.node.Node``), started by ``roscore`` inside
its own process once the master answers: one interpreter instead of two makes ``roscore`` ready
sooner and lets Ctrl-C stop everything at once (``rosrun rosout rosout`` runs it alone). Messages are
relayed without re-serializing (``raw=True`` in, ``publish_raw`` out); each is decoded once, for its
log line (format and rotation: :mod:`ninjemys.master.rosout`).

Like ROS 1's rosout it offers ``/rosout/get_loggers`` and ``/rosout/set_logger_level`` (every Node
does), and does not publish on /rosout itself (rosout.cpp starts with ``NoRosout``).
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from ninjemys.master.rosout import RosoutLog, file_logging_disabled, format_line

log = logging.getLogger(__name__)


class Rosout:
    """The running rosout node (``stop()`` shuts it down)."""

    def __init__(self, master_uri: str, log_dir: Path | None, node_name: str = "/rosout") -> None:
        from ninjemys.idl.loader import get_message_class
        from ninjemys.node import Node

        self.log_class = get_message_class("rosgraph_msgs/Log")
        self.file: RosoutLog | None = None
        if log_dir is not None and not file_logging_disabled():
            self.file = RosoutLog(log_dir / "rosout.log")
        self.node = Node(node_name, master_uri=master_uri, rosout=False)
        try:
            self.omit_topics = bool(self.node.get_param("/rosout/omit_topics", False))
            self.agg = self.node.publisher("/rosout_agg", self.log_class, queue_size=None)
            self.sub = self.node.subscriber(
                "/rosout", self.log_class, self._on_message, queue_size=None, raw=True
            )
        except BaseException:
            self.stop()
            raise

    def _on_message(self, raw: Any) -> None:
        self.agg.publish_raw(raw.data)
        if self.file is None:
            return
        try:
            msg = self.log_class.deserialize_from(bytes(raw.data))
        except Exception as exc:  # a broken publisher must not stop the log
            log.warning("rosout: undecodable message from %s: %s", raw.connection_header.get("callerid"), exc)
            return
        self.file.write(format_line(msg, self.omit_topics))

    def stop(self) -> None:
        try:
            self.node.shutdown("roscore shutting down")
        finally:
            if self.file is not None:
                self.file.close()


def main(argv: list[str] | None = None) -> int:
    """``rosrun rosout rosout``: rosout as a process of its own (``roscore`` runs it in-process).

    Honours the usual node arguments (``__name:=``, ``__master:=``, ...); rosout.log goes to
    ``<log dir>/<run_id>/`` like roscore's.
    """
    import sys

    from ninjemys.errors import MasterError
    from ninjemys.master.client import MasterClient
    from ninjemys.node.cli_args import parse_args
    from ninjemys.roshome import log_directory

    args = parse_args(["rosout", *(sys.argv[1:] if argv is None else argv)])
    name = args.full_name(args.node_name("rosout"))
    log_dir = log_directory()
    try:
        log_dir = log_dir / str(MasterClient(args.master_uri, name, timeout=5.0).get_param("/run_id"))
    except MasterError:
        pass  # no /run_id (a bare master): log straight into the log directory
    log_dir.mkdir(parents=True, exist_ok=True)
    rosout = Rosout(args.master_uri, log_dir, node_name=name)
    try:
        rosout.node.wait_for_shutdown()
    except KeyboardInterrupt:
        pass
    finally:
        rosout.stop()
    return 0
