"""``zenoh-bridge-ros1``: parse, open, run until SIGINT/SIGTERM; one line per error, no traceback."""

from __future__ import annotations

import signal
import sys
from collections.abc import Sequence

from ninjemys.commands import entry
from ninjemys.errors import NinjemysError


def main(argv: Sequence[str] | None = None) -> int:
    from ninjemys.zenoh_bridge.options import OptionsError, parse_options

    try:
        options = parse_options(argv)
    except OptionsError as exc:
        print(f"zenoh-bridge-ros1: error: {exc}", file=sys.stderr)
        return 2
    try:
        import zenoh  # noqa: F401 - the optional dependency, checked before anything starts
    except ImportError:
        print(
            "zenoh-bridge-ros1: error: the Python package eclipse-zenoh is not installed "
            "(pip install 'ninjemys[zenoh]')",
            file=sys.stderr,
        )
        return 1
    if options.ros_hostname:
        import os

        os.environ["ROS_HOSTNAME"] = options.ros_hostname
    master = None
    if options.with_rosmaster:
        from ninjemys.master.core import MasterThread
        from ninjemys.net.addresses import split_uri

        host, port = split_uri(options.ros_master_uri)
        master = MasterThread("0.0.0.0", port, advertise=host)
        try:
            master.start()
        except OSError as exc:
            print(
                f"zenoh-bridge-ros1: error: --with_rosmaster: cannot serve on port {port}: {exc}",
                file=sys.stderr,
            )
            return 1
    from ninjemys.zenoh_bridge.core import ZenohBridge

    def status(line: str) -> None:
        print(f"zenoh-bridge-ros1: {line}", flush=True)

    try:
        bridge = ZenohBridge(options, status)
    except NinjemysError as exc:
        print(f"zenoh-bridge-ros1: error: {exc}", file=sys.stderr)
        return 1

    def on_signal(signum: int, frame: object) -> None:
        bridge.stop()

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    status(
        f"running: ROS master {options.ros_master_uri}, bridge namespace {options.bridge_namespace}, "
        f"Zenoh {options.mode} {bridge.session.zid()}"
    )
    try:
        bridge.run()
    finally:
        bridge.close()
        if master is not None:
            master.stop()
    return 0


console_main = entry(main)

if __name__ == "__main__":
    sys.exit(main())
