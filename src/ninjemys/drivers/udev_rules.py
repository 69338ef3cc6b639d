"""``rosrun rplidar_ros create_udev_rules.sh`` / ``delete_udev_rules.sh``: the lidar's stable name.

rplidar_ros ships two shell scripts that install (or remove) a udev rule linking the RPLIDAR's USB
serial adapter (Silicon Labs CP2102, 10c4:ea60) to ``/dev/rplidar``, then reload udev. Tutorials
tell users to run them, so they are here under the same names, in Python: the rule is written to
``/etc/udev/rules.d/rplidar.rules`` (through ``sudo`` when not root) and udev is told with
``udevadm``, which every systemd and non-systemd distribution has (rplidar_ros' ``service udev``
is missing on some). ``NINJEMYS_UDEV_RULES_DIR`` writes elsewhere and skips udevadm (a test, or a
system image being prepared). See docs/drivers.md for the Arduino's rule.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

RULE_FILE = "rplidar.rules"
RULE = (
    "# RPLIDAR A1/A2/A3 (Silicon Labs CP2102 USB-UART) as /dev/rplidar, written by ninjemys'\n"
    "# rplidar_ros create_udev_rules.sh\n"
    'KERNEL=="ttyUSB*", ATTRS{idVendor}=="10c4", ATTRS{idProduct}=="ea60", MODE:="0666", '
    'SYMLINK+="rplidar"\n'
)


def _target_dir() -> tuple[Path, bool]:
    """The rules directory, and whether this is the system's (then udev is reloaded)."""
    override = os.environ.get("NINJEMYS_UDEV_RULES_DIR")
    return (Path(override), False) if override else (Path("/etc/udev/rules.d"), True)


def _privileged(cmd: list[str]) -> int:
    if os.geteuid() != 0 and shutil.which("sudo"):
        cmd = ["sudo", *cmd]
    return subprocess.run(cmd, check=False).returncode


def _reload() -> int:
    print("Restarting udev")
    for cmd in (["udevadm", "control", "--reload-rules"], ["udevadm", "trigger"]):
        code = _privileged(cmd)
        if code:
            print(f"error: {' '.join(cmd)} failed (exit {code})", file=sys.stderr)
            return code
    return 0


def create_main(argv: list[str] | None = None) -> int:
    """Write the rule and reload udev; 0 on success."""
    directory, system = _target_dir()
    target = directory / RULE_FILE
    print("remap the device serial port(ttyUSBX) to  rplidar")
    print("rplidar usb connection as /dev/rplidar , check it using the command : ls -l /dev|grep ttyUSB")
    print(f"start copy {RULE_FILE} to  {directory}/")
    if system:
        code = subprocess.run(
            ["sudo", "tee", str(target)]
            if os.geteuid() != 0 and shutil.which("sudo")
            else ["tee", str(target)],
            input=RULE,
            text=True,
            stdout=subprocess.DEVNULL,
            check=False,
        ).returncode
        if code:
            print(f"error: cannot write {target} (exit {code})", file=sys.stderr)
            return code
        code = _reload()
        if code:
            return code
    else:
        try:
            directory.mkdir(parents=True, exist_ok=True)
            target.write_text(RULE)
        except OSError as exc:
            print(f"error: cannot write {target}: {exc.strerror or exc}", file=sys.stderr)
            return 1
    print("finish ")
    return 0


def delete_main(argv: list[str] | None = None) -> int:
    """Remove the rule and reload udev; 0 on success (also when there was none)."""
    directory, system = _target_dir()
    target = directory / RULE_FILE
    print("delete remap the device serial port(ttyUSBX) to  rplidar")
    print(f"sudo rm   {target}")
    if system:
        code = _privileged(["rm", "-f", str(target)])
        if code:
            print(f"error: cannot remove {target} (exit {code})", file=sys.stderr)
            return code
        code = _reload()
        if code:
            return code
    else:
        target.unlink(missing_ok=True)
    print("finish  delete")
    return 0
