"""turtlesim_node against ROS turtlesim's documented behaviour, driven over real topics and services."""

from __future__ import annotations

import math
import threading

import pytest

from geometry_msgs.msg import Twist
from ninjemys.errors import ServiceError
from ninjemys.master.client import MasterClient
from ninjemys.sim.world import CENTER, WORLD_SIZE
from ninjemys.testing import wait_until
from std_srvs.srv import Empty
from turtlesim.msg import Pose
from turtlesim.srv import Kill, SetPen, Spawn, TeleportAbsolute


class PoseWatch:
    """Keeps the latest pose of a turtle."""

    def __init__(self, node, name: str) -> None:  # type: ignore[no-untyped-def]
        self.latest: Pose | None = None
        self.count = 0
        self._lock = threading.Lock()
        self.sub = node.subscriber(f"/{name}/pose", Pose, self._on)

    def _on(self, msg: Pose) -> None:
        with self._lock:
            self.latest = msg
            self.count += 1

    def wait_fresh(self, timeout: float = 10.0) -> Pose:
        start = self.count
        wait_until(lambda: self.count > start + 2, timeout, "fresh poses")
        assert self.latest is not None
        return self.latest


def _state(master: str) -> tuple[set[str], set[str], set[str]]:
    pubs, subs, srvs = MasterClient(master, "/probe").call("getSystemState")
    return ({t for t, _ in pubs}, {t for t, _ in subs}, {s for s, _ in srvs})


def _spawn(client, **kw):  # type: ignore[no-untyped-def]
    client.wait_for_service("/spawn", timeout=10)
    return client.service_proxy("/spawn", Spawn)(Spawn._request_class(**kw))


def test_startup_lines_and_interface(turtlesim, master, client) -> None:  # type: ignore[no-untyped-def]
    sim = turtlesim()
    out = sim.wait_for_log("Spawning turtle")
    assert "Starting turtlesim with node name /turtlesim" in out
    assert "Spawning turtle [turtle1] at x=[5.544445], y=[5.544445], theta=[0.000000]" in out
    client.wait_for_service("/turtle1/teleport_relative", timeout=10)
    pubs, subs, srvs = _state(master)
    assert {"/turtle1/pose", "/turtle1/color_sensor"} <= pubs
    assert "/turtle1/cmd_vel" in subs
    assert {"/clear", "/reset", "/spawn", "/kill", "/turtle1/set_pen", "/turtle1/teleport_absolute"} <= srvs
    assert {"/turtlesim/get_loggers", "/turtlesim/set_logger_level"} <= srvs


def test_spawn_kill_and_errors(turtlesim, master, client) -> None:  # type: ignore[no-untyped-def]
    sim = turtlesim()
    assert _spawn(client, x=2.0, y=2.0, theta=0.0, name="").name == "turtle2"
    assert _spawn(client, x=3.0, y=3.0, theta=0.0, name="leo").name == "leo"
    wait_until(lambda: "/leo/pose" in _state(master)[0], what="leo's topics")
    with pytest.raises(ServiceError, match=r"A turtle named \[leo\] already exists"):
        _spawn(client, x=1.0, y=1.0, theta=0.0, name="leo")
    kill = client.service_proxy("/kill", Kill)
    kill(Kill._request_class(name="leo"))
    pubs, subs, srvs = _state(master)
    assert "/leo/pose" not in pubs and "/leo/color_sensor" not in pubs
    assert "/leo/cmd_vel" not in subs
    assert not any(s.startswith("/leo/") for s in srvs)
    with pytest.raises(ServiceError, match=r"Tried to kill turtle \[leo\], which does not exist"):
        kill(Kill._request_class(name="leo"))
    assert sim.proc.poll() is None


def test_one_cmd_vel_moves_one_unit_then_stops(turtlesim, client) -> None:  # type: ignore[no-untyped-def]
    turtlesim()
    watch = PoseWatch(client, "turtle1")
    start = watch.wait_fresh()
    assert (start.x, start.y) == (pytest.approx(CENTER, abs=1e-5), pytest.approx(CENTER, abs=1e-5))
    pub = client.publisher("/turtle1/cmd_vel", Twist, queue_size=1)
    wait_until(lambda: pub.get_num_connections() > 0, what="turtlesim to subscribe")
    cmd = Twist()
    cmd.linear.x = 1.0
    pub.publish(cmd)
    wait_until(lambda: watch.latest.linear_velocity > 0, what="the turtle to move")
    wait_until(lambda: watch.latest.linear_velocity == 0.0, timeout=5, what="the command to time out")
    end = watch.wait_fresh()
    assert end.x - start.x == pytest.approx(1.0, rel=0.02)
    assert end.y == pytest.approx(start.y, abs=1e-4)
    # NaN is ignored: the turtle stays where it is and the node keeps running
    bad = Twist()
    bad.linear.x = math.nan
    pub.publish(bad)
    after = watch.wait_fresh()
    assert math.isfinite(after.x) and after.x == pytest.approx(end.x, abs=1e-6)


def test_teleport_wall_clamp_and_reset(turtlesim, master, client) -> None:  # type: ignore[no-untyped-def]
    sim = turtlesim()
    watch = PoseWatch(client, "turtle1")
    client.wait_for_service("/turtle1/teleport_absolute", timeout=10)
    client.service_proxy("/turtle1/teleport_absolute", TeleportAbsolute)(
        TeleportAbsolute._request_class(x=10.5, y=3.0, theta=0.0)
    )
    pose = watch.wait_fresh()
    assert (pose.x, pose.y, pose.theta) == (pytest.approx(10.5), pytest.approx(3.0), pytest.approx(0.0))
    pub = client.publisher("/turtle1/cmd_vel", Twist, queue_size=1)
    wait_until(lambda: pub.get_num_connections() > 0, what="turtlesim to subscribe")
    cmd = Twist()
    cmd.linear.x = 3.0
    pub.publish(cmd)
    sim.wait_for_log("Oh no! I hit the wall! (Clamping from [x=")
    wait_until(lambda: watch.latest.x == pytest.approx(WORLD_SIZE, abs=1e-5), what="clamped pose")

    _spawn(client, x=1.0, y=1.0, theta=0.0, name="")
    client.service_proxy("/reset", Empty)(Empty._request_class())
    pubs, _subs, srvs = _state(master)
    assert "/turtle2/pose" not in pubs and "/turtle2/set_pen" not in srvs
    pose = watch.wait_fresh()
    assert (pose.x, pose.y) == (pytest.approx(CENTER, abs=1e-5), pytest.approx(CENTER, abs=1e-5))
    assert _spawn(client, x=1.0, y=1.0, theta=0.0, name="").name == "turtle2"  # the counter restarted


def test_set_pen_service(turtlesim, client) -> None:  # type: ignore[no-untyped-def]
    turtlesim()
    client.wait_for_service("/turtle1/set_pen", timeout=10)
    set_pen = client.service_proxy("/turtle1/set_pen", SetPen)
    set_pen(SetPen._request_class(r=255, g=0, b=0, width=4, off=0))
    client.service_proxy("/turtle1/teleport_absolute", TeleportAbsolute)(
        TeleportAbsolute._request_class(x=8.0, y=CENTER, theta=0.0)
    )
    from turtlesim.msg import Color

    seen: list[Color] = []
    client.subscriber("/turtle1/color_sensor", Color, seen.append)
    wait_until(lambda: seen, what="color sensor")
    assert (seen[-1].r, seen[-1].g, seen[-1].b) == (255, 0, 0)


def test_bad_input_gets_error_responses_and_no_crash(turtlesim, client) -> None:  # type: ignore[no-untyped-def]
    sim = turtlesim()
    with pytest.raises(ServiceError, match="non-finite"):
        _spawn(client, x=math.nan, y=1.0, theta=0.0, name="")
    client.wait_for_service("/turtle1/teleport_absolute", timeout=10)
    with pytest.raises(ServiceError, match="non-finite"):
        client.service_proxy("/turtle1/teleport_absolute", TeleportAbsolute)(
            TeleportAbsolute._request_class(x=math.inf, y=1.0, theta=0.0)
        )
    # the node is still serving, and the failed spawn did not use up a name
    assert _spawn(client, x=1.0, y=1.0, theta=0.0, name="").name == "turtle2"
    assert sim.proc.poll() is None


def test_clear_reads_background_params(turtlesim, client) -> None:  # type: ignore[no-untyped-def]
    from turtlesim.msg import Color

    turtlesim()
    seen: list[Color] = []
    client.subscriber("/turtle1/color_sensor", Color, seen.append)
    wait_until(lambda: seen, what="color sensor")
    assert (seen[-1].r, seen[-1].g, seen[-1].b) == (69, 86, 255)
    client.set_param("/turtlesim/background_r", 255)
    client.set_param("/turtlesim/background_g", 255)
    client.set_param("/turtlesim/background_b", 0)
    client.wait_for_service("/clear", timeout=10)
    client.service_proxy("/clear", Empty)(Empty._request_class())
    wait_until(lambda: (seen[-1].r, seen[-1].g, seen[-1].b) == (255, 255, 0), what="new background")
