"""The simulator draws its camera images straight into its publishers' loans (shm_loan): an SHMROS
subscriber's frames are never copied into its ring, and every subscriber, over shared memory, over
TCPROS or through image_transport's compressed topic, gets the very bytes that were rendered, while
the robot moves and while it stands still (a still camera's frame copied into the next loan)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from ninjemys.idl.loader import get_message_class
from ninjemys.image_transport.compressed import decode
from ninjemys.node import Node, shm_link, shm_ring
from ninjemys.node.log import NodeLog
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model
from ninjemys.sim.simcore import Simulation
from ninjemys.sim.world2d import load_world
from ninjemys.sim.worlds import world_path
from ninjemys.testing import run_master, wait_until

pytestmark = pytest.mark.skipif(not shm_ring.available(), reason="SHMROS needs Linux and /dev/shm")

Image = get_message_class("sensor_msgs/Image")
CompressedImage = get_message_class("sensor_msgs/CompressedImage")
COLOUR, DEPTH = "/camera/color/image_raw", "/camera/depth/image_rect_raw"


@pytest.fixture
def sim(monkeypatch: pytest.MonkeyPatch) -> Iterator[tuple[SimNode, list[tuple[bytes, bytes]], Any]]:
    """The simulator in the square world (no moving obstacle: a robot that stands still sees the same
    frame; renders recorded as bytes) and a factory of client nodes."""
    monkeypatch.setenv("NINJEMYS_SHM", "1")
    monkeypatch.delenv("NINJEMYS_UNIXROS", raising=False)
    with run_master() as master:
        nodes = [Node("camera_loan_sim", master_uri=master)]

        def client(name: str) -> Node:
            nodes.append(Node(name, master_uri=master))
            return nodes[-1]

        try:
            sn = SimNode(
                nodes[0],
                NodeLog(nodes[0].name),
                Simulation(load_world(world_path("square")), 0.01),
                0.0,
                None,
            )
            sn.add_robot("puzzlebot", load_robot_model("puzzlebot"), 0.0, 0.0, 0.0, False)
            rendered: list[tuple[bytes, bytes]] = []
            camera = sn.sim.robots["puzzlebot"].camera
            assert camera is not None
            draw = camera.render

            def recorded(*args: Any, **kwargs: Any) -> tuple[np.ndarray, np.ndarray]:
                images = draw(*args, **kwargs)
                rendered.append((images[0].tobytes(), images[1].tobytes()))
                return images

            camera.render = recorded  # type: ignore[method-assign]
            yield sn, rendered, client
        finally:
            for node in reversed(nodes):
                node.shutdown("test over")


def _ring(sn: SimNode, topic: str) -> shm_ring.WriterRing:
    conns = sn.node._publications[topic].connections
    ring = next(c for c in conns if isinstance(c, shm_link.ShmPubConnection)).ring
    assert ring is not None
    return ring


def test_images_are_drawn_into_loans_and_every_subscriber_gets_the_rendered_bytes(
    sim: tuple[SimNode, list[tuple[bytes, bytes]], Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    sn, rendered, client = sim
    got: dict[str, list[bytes]] = {"shm": [], "tcp": [], "shm_depth": [], "tcp_depth": [], "png": []}

    def into(key: str) -> Any:
        return lambda m: got[key].append(bytes(m.data))

    shm = client("shm_viewer")
    shm.subscriber(COLOUR, Image, into("shm"), queue_size=100)
    shm.subscriber(DEPTH, Image, into("shm_depth"), queue_size=100)
    pubs = sn.io["puzzlebot"].pubs
    wait_until(
        lambda: pubs["image"].get_num_connections() == pubs["depth"].get_num_connections() == 1,
        10,
        "the shared-memory subscribers",
    )
    monkeypatch.setenv("NINJEMYS_SHM", "0")  # the next subscribers connect over TCPROS
    tcp = client("tcp_viewer")
    tcp.subscriber(COLOUR, Image, into("tcp"), queue_size=100)
    tcp.subscriber(DEPTH, Image, into("tcp_depth"), queue_size=100)
    sn.node.set_param(COLOUR + "/compressed/format", "png")
    tcp.subscriber(
        COLOUR + "/compressed",
        CompressedImage,
        lambda m: got["png"].append(bytes(decode(m).data)),
        queue_size=100,
    )
    wait_until(
        lambda: (
            pubs["image"].get_num_connections() == 2
            and pubs["depth"].get_num_connections() == 2
            and pubs["image_compressed"].get_num_connections() == 1
        ),
        10,
        "the subscribers",
    )
    robot = sn.io["puzzlebot"].robot

    def delivered() -> bool:
        return all(len(v) == len(rendered) for v in got.values())

    def frames(n: int, move: bool) -> None:
        """``n`` frames, each read by every subscriber before the next (so that a free slot is
        there for every loan: a subscriber that lags keeps its slots, and the loan then falls back
        to the heap and a copy, as it should, but not what is tested here)."""
        for _ in range(n):
            before = len(rendered)
            while len(rendered) == before:  # 30 frames a simulated second: every 3 or 4 steps
                sn._step_and_publish()
            wait_until(delivered, 20, f"frame {len(rendered)} on every subscription")
            if move:
                robot.x += 0.03
                robot.yaw += 0.05

    frames(1, False)  # the first frame's loans make the rings
    copied: list[int] = []
    for topic in (COLOUR, DEPTH):
        ring = _ring(sn, topic)
        real_put = ring.put

        def counted(parts: Any, length: int, wait: float = 0.0, put: Any = real_put) -> Any:
            copied.append(length)
            return put(parts, length, wait)

        ring.put = counted  # type: ignore[method-assign]
    frames(4, False)  # standing still: the last frame copied into each new loan
    frames(6, True)  # driving: each frame drawn in its loan
    frames(3, False)
    assert copied == []  # no image was copied into a ring: they were drawn in their slots
    assert got["shm"] == got["tcp"] == got["png"] == [rgb for rgb, _ in rendered]
    assert got["shm_depth"] == got["tcp_depth"] == [depth for _, depth in rendered]
    assert len(set(got["shm"])) >= 7  # the frames changed as the robot drove


def test_a_still_camera_copies_its_frame_into_new_arrays_and_bad_arrays_are_refused() -> None:
    sim = Simulation(load_world(world_path("office")), 0.01)
    robot = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, 0.3)
    cam = robot.camera
    assert cam is not None
    plain = sim.render(robot)
    shape = (cam.height, cam.width)
    for _ in range(2):  # drawn, then the camera stood still: copied
        rgb, depth = np.full((*shape, 3), 7, np.uint8), np.full(shape, 7, np.uint16)
        with cam.drawing_into(rgb, depth):
            got = sim.render(robot)
        assert got[0] is rgb and got[1] is depth
        assert np.array_equal(rgb, plain[0]) and np.array_equal(depth, plain[1])
    with cam.drawing_into(None, depth):  # only the depth image drawn into an array of ours
        got = sim.render(robot, colour=False)
    assert got[0].size == 0 and got[1] is depth
    with pytest.raises(ValueError, match=r"colour image .* uint8 array of shape \(240, 320, 3\)"):
        with cam.drawing_into(np.zeros((240, 320), np.uint8), None):
            pass
    read_only = np.zeros(shape, np.uint16)
    read_only.flags.writeable = False
    with pytest.raises(ValueError, match="depth image .* read-only"):
        with cam.drawing_into(None, read_only):
            pass
    again = sim.render(robot)  # outside the block: new arrays again, the same images
    assert again[0] is not rgb and again[1] is not depth
    assert np.array_equal(again[0], plain[0]) and np.array_equal(again[1], plain[1])
