"""ROS across machines, for real: three hosts (network namespaces), the master on one, nodes on the
others, with ROS_IP, with ROS_HOSTNAME and with neither; a name that does not resolve; `rosnode
machine`; a lossy, slow link; a cut link that heals; a real rospy node across hosts."""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import testing

from .netns import Network, unavailable

WHY = unavailable()
pytestmark = pytest.mark.skipif(WHY is not None, reason=WHY or "")

HERE = Path(__file__).parent
VENV_BIN = Path(sys.executable).parent
NODE = [sys.executable, str(HERE / "node_proc.py")]


@pytest.fixture(scope="module")
def net() -> Iterator[Network]:
    network = Network()
    try:
        yield network
    finally:
        network.close()


def _env(net: Network, host: str, naming: str, master: str = "hosta") -> dict[str, str]:
    """The environment of a process on ``host``: ROS_IP, ROS_HOSTNAME or neither (``naming``)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROS_")}
    env["ROS_MASTER_URI"] = f"http://{net.ip[master]}:11311/"
    env["PYTHONUNBUFFERED"] = "1"
    if naming == "ip":
        env["ROS_IP"] = net.ip[host]
    elif naming == "hostname":
        env["ROS_HOSTNAME"] = host
    env["ROS_HOME"] = env["ROS_LOG_DIR"] = f"/tmp/nj_multihost_{os.getpid()}_{host}"
    return env


@pytest.fixture
def master(net: Network) -> Iterator[None]:
    proc = net.run("hosta", [str(VENV_BIN / "roscore"), "-p", "11311"], _env(net, "hosta", "ip"), "roscore")
    try:
        assert proc.wait_line(lambda line: "started core service" in line or "master" in line.lower(), 30), (
            proc.text()
        )
        time.sleep(0.5)
        yield
    finally:
        proc.stop()
        net.procs.remove(proc)


def _stream(net: Network, naming: str, topic: str) -> tuple:
    talker = net.run("hostb", [*NODE, "talker", topic, "b"], _env(net, "hostb", naming), "talker")
    listener = net.run("hostc", [*NODE, "listener", topic, "c"], _env(net, "hostc", naming), "listener")
    return talker, listener


@pytest.mark.parametrize("naming", ["ip", "hostname", "neither"])
def test_master_on_one_host_nodes_on_two_others(net: Network, master: None, naming: str) -> None:
    talker, listener = _stream(net, naming, f"/chatter_{naming}")
    try:
        assert listener.wait_line(lambda line: line.startswith("got b "), timeout=30), (
            talker.text(),
            listener.text(),
        )
        # what the master knows: the talker's URI names host b as that set-up says
        expected = {"ip": net.ip["hostb"], "hostname": "hostb", "neither": "hostb"}[naming]
        lookup = net.run(
            "hostc", [str(VENV_BIN / "rosnode"), "info", "/talker_b"], _env(net, "hostc", naming), "info"
        )
        assert lookup.wait_line(lambda line: f"http://{expected}:" in line, timeout=20), lookup.text()
    finally:
        talker.stop()
        listener.stop()


def test_rosnode_machine_lists_the_nodes_of_each_host(net: Network, master: None) -> None:
    talker, listener = _stream(net, "hostname", "/chatter_machine")
    try:
        assert listener.wait_line(lambda line: line.startswith("got b "), timeout=30)
        out = net.run(
            "hosta", [str(VENV_BIN / "rosnode"), "machine", "hostb"], _env(net, "hosta", "ip"), "machine"
        )
        assert out.wait_line(lambda line: line.strip() == "/talker_b", timeout=20), out.text()
        out.popen.wait(10)
        assert "/listener_c" not in out.text()
    finally:
        talker.stop()
        listener.stop()


def test_a_name_that_does_not_resolve_gets_one_clear_error(net: Network, master: None) -> None:
    env = _env(net, "hostb", "ip")
    del env["ROS_IP"]
    env["ROS_HOSTNAME"] = "nosuchhost.invalid"
    talker = net.run("hostb", [*NODE, "talker", "/chatter_bad", "b"], env, "bad talker")
    try:
        line = talker.wait_line(lambda line: "does not resolve" in line, timeout=30)
        assert line is not None, talker.text()
        assert "ROS_HOSTNAME [nosuchhost.invalid]" in line and "ROS_IP" in line
        time.sleep(1.0)
        assert talker.text().count("does not resolve") == 1
    finally:
        talker.stop()


def test_a_slow_lossy_link_still_delivers_in_order(net: Network, master: None) -> None:
    talker, listener = _stream(net, "ip", "/chatter_netem")
    try:
        assert listener.wait_line(lambda line: line.startswith("got b "), timeout=30)
        why = net.netem("hostb", "delay", "80ms", "loss", "10%")
        if why is not None:
            pytest.skip(f"this kernel cannot shape links ({why})")
        mark = len(listener.lines)
        time.sleep(4.0)
        got = [int(line.split()[2]) for line in listener.lines[mark:] if line.startswith("got b ")]
        assert len(got) >= 20, listener.text()[-500:]
        assert got == sorted(got) and len(set(got)) == len(got)  # TCP: late, never reordered or doubled
    finally:
        net.clear_netem("hostb")
        talker.stop()
        listener.stop()


def test_a_cut_link_heals_within_five_seconds_of_restore(net: Network, master: None) -> None:
    talker, listener = _stream(net, "ip", "/chatter_cut")
    try:
        assert listener.wait_line(lambda line: line.startswith("got b "), timeout=30)
        net.cut("hostb")
        time.sleep(3.0)
        mark = len(listener.lines)
        net.restore("hostb")
        restored = time.time()
        line = listener.wait_line(lambda text: text.startswith("got b "), timeout=15, start=mark)
        assert line is not None, listener.text()[-500:]
        healed = float(line.split()[3]) - restored
        print(f"stream resumed {healed:.2f} s after the link came back")
        assert healed < 5.0
    finally:
        talker.stop()
        listener.stop()


@pytest.mark.ros1
def test_a_real_rospy_talker_on_another_host(net: Network, master: None) -> None:
    if not testing.have_ros1():
        pytest.skip("Debian's ROS 1 is not installed")
    script = (
        "import rospy, std_msgs.msg as m\n"
        "rospy.init_node('rospy_talker')\n"
        "p = rospy.Publisher('/chatter_rospy', m.String, queue_size=10)\n"
        "r = rospy.Rate(20)\n"
        "i = 0\n"
        "while not rospy.is_shutdown():\n"
        "    p.publish(m.String('rospy %d' % i)); i += 1; r.sleep()\n"
    )
    env = testing.ros1_env(f"http://{net.ip['hosta']}:11311/", ROS_IP=net.ip["hostb"])
    env.pop("ROS_HOSTNAME", None)
    talker = net.run("hostb", [testing.ROS1_PYTHON, "-c", script], env, "rospy talker")
    listener = net.run(
        "hostc", [*NODE, "listener", "/chatter_rospy", "c"], _env(net, "hostc", "ip"), "listener"
    )
    try:
        assert listener.wait_line(lambda line: line.startswith("got rospy "), timeout=40), (
            talker.text(),
            listener.text(),
        )
    finally:
        talker.stop()
        listener.stop()


def _sshd(net: Network, tmp: Path) -> tuple[Path, object]:
    """An sshd on hostb that lets root in with a key of the test's own; returns the client's home."""
    import shutil
    import subprocess

    if shutil.which("sshd") is None and not Path("/usr/sbin/sshd").exists():
        pytest.skip("sshd is not installed (make test installs openssh-server)")
    keys = tmp / "keys"
    home = tmp / "home"
    (home / ".ssh").mkdir(parents=True)
    keys.mkdir()
    for name in ("host", "client"):
        subprocess.run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", str(keys / name)], check=True)
    (keys / "authorized_keys").write_text((keys / "client.pub").read_text())
    config = keys / "sshd_config"
    config.write_text(
        f"Port 22\nListenAddress {net.ip['hostb']}\nHostKey {keys / 'host'}\nAuthorizedKeysFile {keys / 'authorized_keys'}\n"
        f"PermitRootLogin prohibit-password\nPasswordAuthentication no\nKbdInteractiveAuthentication no\n"
        f"StrictModes no\nUsePAM no\nPidFile {keys / 'sshd.pid'}\n"
    )
    shutil.copy(keys / "client", home / ".ssh" / "id_ed25519")
    (home / ".ssh" / "id_ed25519").chmod(0o600)
    (home / ".ssh" / "config").write_text(
        "Host *\n  StrictHostKeyChecking no\n  UserKnownHostsFile /dev/null\n  LogLevel ERROR\n"
    )
    Path("/run/sshd").mkdir(exist_ok=True)  # sshd's privilege-separation directory
    sshd = net.run("hostb", ["/usr/sbin/sshd", "-D", "-e", "-f", str(config)], dict(os.environ), "sshd")
    time.sleep(0.5)
    return home, sshd


def test_roslaunch_starts_a_node_on_another_machine_over_ssh(
    net: Network, master: None, tmp_path: Path
) -> None:
    home, sshd = _sshd(net, tmp_path)
    loader = tmp_path / "env.sh"
    # the remote machine's set-up, as a user's env-loader makes it: ninjemys on PATH, its own address
    loader.write_text(f'#!/bin/sh\nexport PATH="{VENV_BIN}:$PATH" ROS_IP={net.ip["hostb"]}\nexec "$@"\n')
    loader.chmod(0o755)
    launch = tmp_path / "two_machines.launch"
    launch.write_text(
        f'<launch>\n  <machine name="robot" address="hostb" user="root" env-loader="{loader}"/>\n'
        '  <node machine="robot" pkg="rospy_tutorials" type="talker" name="remote_talker"/>\n'
        '  <node pkg="rospy_tutorials" type="listener" name="local_listener" output="screen"/>\n</launch>\n'
    )
    env = _env(net, "hosta", "ip")
    env["ROS_HOME"] = str(tmp_path / "ros_home")
    # ssh reads the client key and config from the user's home: give this roslaunch its own /root
    argv = ["unshare", "--mount", "sh", "-c", 'mount --bind "$0" /root && exec "$@"', str(home),
            str(VENV_BIN / "roslaunch"), str(launch)]  # fmt: skip
    roslaunch = net.run("hosta", argv, env, "roslaunch")
    try:
        heard = roslaunch.wait_line(lambda line: "I heard hello world" in line, timeout=60)
        assert heard is not None, roslaunch.text()[-3000:] + "\n--- sshd ---\n" + sshd.text()  # type: ignore[attr-defined]
        info = net.run(
            "hosta", [str(VENV_BIN / "rosnode"), "machine", "hostb"], _env(net, "hosta", "ip"), "machine"
        )
        assert info.wait_line(lambda line: line.strip() == "/remote_talker", timeout=20), info.text()
    finally:
        roslaunch.stop()
        sshd.stop()  # type: ignore[attr-defined]
