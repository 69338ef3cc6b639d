"""The simulator's camera lights surfaces as Gazebo does (issue 23 [3/6], CAM3): Gazebo's sun is a
directional light, so a surface's colour is material x (scene ambient + light diffuse x max(0, n . -d))
clamped, whatever its distance. Udacity's "Go Chase It" ball_chaser looks for pixels equal to 255 in
``camera/rgb/image_raw``: a white ball must give them at 1, 2 and 4 m, and a ball-chaser node of the
course's pattern must drive to the ball in our simulator. Worlds' own ``<light>`` and
``<scene><ambient>`` are honoured; depth images do not depend on light."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest
from camera_reference import assert_matches_reference, reference_render
from gazebo_helpers import two_wheel_urdf

from ninjemys.idl.loader import get_message_class
from ninjemys.node import Node
from ninjemys.node.log import NodeLog
from ninjemys.sim.lighting import GAZEBO_SUN
from ninjemys.sim.puzzlebot_node import SimNode
from ninjemys.sim.robot_model import load_robot_model, model_from_urdf
from ninjemys.sim.sdf import parse_sdf_world
from ninjemys.sim.simcore import Simulation
from ninjemys.testing import run_master, wait_until

Image = get_message_class("sensor_msgs/Image")
Twist = get_message_class("geometry_msgs/Twist")
NO_ENV = {"HOME": "/nonexistent"}
#: -d, the unit vector toward Gazebo's default sun (direction -0.5 0.1 -0.9)
TOWARD_SUN = np.array(GAZEBO_SUN.toward())


def model(name: str, pose: str, geometry: str, material: str, static: bool = True) -> str:
    return (
        f'<model name="{name}"><static>{int(static)}</static><pose>{pose}</pose><link name="link">'
        f'<collision name="c"><geometry>{geometry}</geometry></collision>'
        f'<visual name="v"><geometry>{geometry}</geometry><material><script>'
        "<uri>file://media/materials/scripts/gazebo.material</uri>"
        f"<name>{material}</name></script></material></visual></link></model>"
    )


def world_text(
    *models: str, lights: str = "<include><uri>model://sun</uri></include>", scene: str = ""
) -> str:
    return (
        '<?xml version="1.0"?><sdf version="1.6"><world name="default">'
        + lights
        + "<include><uri>model://ground_plane</uri></include>"
        + scene
        + "".join(models)
        + "</world></sdf>"
    )


#: a "Go Chase It" room: 8 x 8 m of grey walls, a white ball (radius 0.1 m) resting on the floor
BALL_AT = (-1.0, 0.8)
ROOM = [
    model("wall_n", "0 4 0.5 0 0 0", "<box><size>8 0.15 1</size></box>", "Gazebo/Grey"),
    model("wall_s", "0 -4 0.5 0 0 0", "<box><size>8 0.15 1</size></box>", "Gazebo/Grey"),
    model("wall_e", "4 0 0.5 0 0 0", "<box><size>0.15 8 1</size></box>", "Gazebo/Grey"),
    model("wall_w", "-4 0 0.5 0 0 0", "<box><size>0.15 8 1</size></box>", "Gazebo/Grey"),
    model(
        "white_ball",
        f"{BALL_AT[0]} {BALL_AT[1]} 0.1 0 0 0",
        "<sphere><radius>0.1</radius></sphere>",
        "Gazebo/White",
    ),
]


def expected(
    colour: float, normal: tuple[float, float, float], ambient: float = 0.4, diffuse: float = 0.8
) -> int:
    """Gazebo's rule for one channel of a grey material under the default sun."""
    lambert = max(0.0, float(np.dot(normal, TOWARD_SUN)))
    return int(min(255.0, math.floor(colour * (ambient + diffuse * lambert) + 0.5)))


@pytest.mark.parametrize("distance", [1.0, 2.0, 4.0])
def test_a_white_ball_shows_255_on_its_sun_facing_top_at_any_distance(distance: float) -> None:
    """The PuzzleBot on the ball's sunny side (the sun shines from +x), facing it: white pixels, all
    three channels 255, inside the ball's columns; the old renderer's distance darkening gave 254 and
    less beyond 1.5 m."""
    sim = Simulation(parse_sdf_world(world_text(*ROOM), "room.world", NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, math.pi)
    assert r.camera is not None and r.model.camera is not None
    cam_x = r.model.camera.pose.xyz[0]
    r.x, r.y = BALL_AT[0] + 0.1 + distance + cam_x, BALL_AT[1]  # the camera `distance` from the ball's face
    rgb, depth = sim.render(r)
    white = (rgb == 255).all(axis=2)
    assert white.sum() >= 2, f"no white pixel at {distance} m"
    cols = np.flatnonzero(white.any(axis=0))
    u = r.camera.width // 2
    assert abs(cols.mean() - u) < 3  # the ball, straight ahead
    # the ball's pixels are at its depth (light does not change depth)
    rows = np.flatnonzero(white[:, u]) if white[:, u].any() else np.flatnonzero(white.any(axis=1))
    assert abs(int(depth[rows[0], u]) - round(distance * 1000)) < 30
    # the rest of the image has no white pixel: the floor and the walls are darker
    others = white.copy()
    others[:, cols.min() : cols.max() + 1] = False
    assert not others.any()


def test_a_walls_colour_is_the_formulas_at_any_distance() -> None:
    """A white wall facing +x, lit by the default sun: 255 x (0.4 + 0.8 x n . -d) with n = (1, 0, 0),
    201, at 1, 3 and 6 m; the same wall's other face, turned from the sun, the ambient alone, 102.
    The floor has one colour at every distance."""
    wall = model("wall", "-3 0 1 0 0 0", "<box><size>0.2 6 2</size></box>", "Gazebo/White")
    sim = Simulation(parse_sdf_world(world_text(wall), "wall.world", NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, math.pi)
    assert r.camera is not None and r.model.camera is not None
    cam_x = r.model.camera.pose.xyz[0]
    sunny = expected(255, (1.0, 0.0, 0.0))
    assert sunny == 201
    u, v = r.camera.width // 2, int(r.camera.cy) - 5
    floors = set()
    for distance in (1.0, 3.0, 6.0):
        r.x = -2.9 + distance + cam_x
        rgb, depth = sim.render(r)
        assert tuple(rgb[v, u]) == (sunny, sunny, sunny), (distance, rgb[v, u])
        assert abs(int(depth[v, u]) - round(distance * 1000)) <= 1
        floors.add(tuple(rgb[-1, u]))
    # the floor: Gazebo's grey ground plane (0.7) lit from above
    grey = expected(179, (0.0, 0.0, 1.0))
    assert floors == {(grey, grey, grey)}
    r.x, r.yaw = -5.0, 0.0  # behind the wall, looking at its face turned from the sun
    r.x = -3.1 - 2.0 - cam_x
    rgb, _ = sim.render(r)
    assert tuple(rgb[v, u]) == (102, 102, 102)


def test_a_worlds_own_lights_and_ambient_are_honoured() -> None:
    """``<scene><ambient>`` and a directional ``<light>`` of the world's own replace Gazebo's
    defaults: ambient 0.2 and a light straight down of diffuse 0.6 leave a wall at 0.2 x 255 and
    a box's lid at 0.8 x 255; ``<background>`` is the sky."""
    light = (
        '<light type="directional" name="overhead"><diffuse>0.6 0.6 0.6 1</diffuse>'
        "<direction>0 0 -1</direction></light>"
    )
    scene = "<scene><ambient>0.2 0.2 0.2 1</ambient><background>0.1 0.2 0.3 1</background></scene>"
    box = model("low_box", "-1.5 0 0.05 0 0 0", "<box><size>0.6 0.6 0.1</size></box>", "Gazebo/White")
    wall = model("wall", "-4 0 1 0 0 0", "<box><size>0.2 6 2</size></box>", "Gazebo/White")
    world = parse_sdf_world(world_text(box, wall, lights=light, scene=scene), "lit.world", NO_ENV)
    sim = Simulation(world)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 0.0, 0.0, math.pi)
    assert r.camera is not None
    rgb, _ = sim.render(r)
    u = r.camera.width // 2
    column = [tuple(int(c) for c in p) for p in rgb[:, u]]
    assert (51, 51, 51) in column  # the wall: 0.2 x 255
    assert (204, 204, 204) in column  # the box's lid: (0.2 + 0.6) x 255
    assert column[0] == (26, 51, 76)  # the sky: the scene's background
    # nothing else than the box, the wall, the floor, the sky
    floor = (143, 143, 143)  # the ground plane's grey, 179 x 0.8
    assert set(column) <= {(51, 51, 51), (204, 204, 204), (26, 51, 76), floor}, set(column)


def test_spheres_and_cylinders_agree_with_the_per_pixel_reference() -> None:
    """The fast renderer's colours and depths against the pixel-by-pixel reference (Gazebo's rule
    written out per pixel), in a room with the white ball, a green cylinder and a red box seen from
    the sun's side and from the other, near and far."""
    extra = [
        model(
            "can",
            "-1.5 -0.8 0.4 0 0 0",
            "<cylinder><radius>0.2</radius><length>0.8</length></cylinder>",
            "Gazebo/Green",
        ),
        model("crate", "-2.5 0.2 0.25 0 0 0.5", "<box><size>0.5 0.5 0.5</size></box>", "Gazebo/Red"),
    ]
    sim = Simulation(parse_sdf_world(world_text(*ROOM, *extra), "room.world", NO_ENV))
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 1.0, 0.3, math.pi)
    for x, y, yaw in ((1.0, 0.3, math.pi), (-0.2, 0.6, math.pi), (-3.0, 0.0, 0.0), (-0.6, 0.8, math.pi)):
        r.x, r.y, r.yaw = x, y, yaw
        assert_matches_reference(sim, r)


#: the Go Chase It robot's camera, as its my_robot.gazebo has it: topic camera/rgb/image_raw
CAMERA_LINK = """
  <link name="camera"><collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
  <joint name="camera_joint" type="fixed"><parent link="base_link"/><child link="camera"/>
    <origin xyz="0.11 0 0.05"/></joint>
  <gazebo reference="camera"><sensor type="camera" name="camera1"><update_rate>10.0</update_rate>
    <camera name="head"><horizontal_fov>1.3962634</horizontal_fov>
      <image><width>160</width><height>120</height><format>R8G8B8</format></image>
      <clip><near>0.02</near><far>300</far></clip></camera>
    <plugin name="camera_controller" filename="libgazebo_ros_camera.so">
      <alwaysOn>true</alwaysOn><updateRate>0.0</updateRate><cameraName>camera</cameraName>
      <imageTopicName>rgb/image_raw</imageTopicName><cameraInfoTopicName>rgb/camera_info</cameraInfoTopicName>
      <frameName>camera</frameName></plugin></sensor></gazebo>
"""


class BallChaser:
    """The course's ball_chaser pattern: look at each image for a white pixel (255 in all three
    channels); by the third of the image it is in, turn left, drive ahead or turn right; with no
    white pixel, stop. (The course sends the command through a ``command_robot`` service that
    publishes it on cmd_vel; the service hop is left out.)"""

    def __init__(self, node: Node) -> None:
        self.pub = node.publisher("/cmd_vel", Twist, queue_size=10)
        self.images = 0
        self.saw_ball = 0
        self.lock = threading.Lock()
        node.subscriber("/camera/rgb/image_raw", Image, self.process_image, queue_size=1)

    def process_image(self, img: Image) -> None:  # type: ignore[valid-type]
        rows = np.frombuffer(bytes(img.data), dtype=np.uint8).reshape(img.height, img.step)
        pixels = rows[:, : img.width * 3].reshape(img.height, img.width, 3)
        white = np.flatnonzero((pixels == 255).all(axis=2).reshape(-1))
        cmd = Twist()
        if len(white):
            column = int(white[0]) % img.width  # the first white pixel, row by row, as the course's loop
            if column < img.width / 3:
                cmd.angular.z = 0.5
            elif column > 2 * img.width / 3:
                cmd.angular.z = -0.5
            else:
                cmd.linear.x = 0.3
        self.pub.publish(cmd)
        with self.lock:
            self.images += 1
            self.saw_ball += bool(len(white))


def test_a_ball_chaser_node_drives_to_the_white_ball() -> None:
    """A robot with the course's camera (``camera/rgb/image_raw``) 3.1 m from the ball, which is
    off to its right: the chaser turns toward it, drives, and ends up at the ball."""
    urdf = two_wheel_urdf("my_robot", CAMERA_LINK)
    world = parse_sdf_world(world_text(*ROOM), "room.world", NO_ENV)
    with run_master() as master:
        node = Node("gazebo", master_uri=master)
        client = Node("ball_chaser", master_uri=master)
        try:
            sn = SimNode(node, NodeLog(node.name), Simulation(world), 2.0, None)
            sn.add_robot("my_robot", model_from_urdf(urdf, "my_robot.urdf"), 2.0, 0.0, math.pi, False)
            chaser = BallChaser(client)
            robot = sn.sim.robots["my_robot"]
            wait_until(lambda: chaser.pub.get_num_connections() > 0, 10, "the simulator took cmd_vel")
            sn.stepper.start()
            bx, by = BALL_AT

            def at_ball() -> bool:
                return math.hypot(robot.x - bx, robot.y - by) < 0.35

            wait_until(at_ball, 60, "the robot reached the ball")
            with chaser.lock:
                assert chaser.saw_ball >= 3 and chaser.images >= chaser.saw_ball
            assert robot.y > 0.3  # it turned toward the ball (to its right, +y) on the way
        finally:
            sn.stepper.stop()
            client.shutdown("test over")
            node.shutdown("test over")


def test_a_world_with_a_moving_obstacle_is_lit_the_same_frame_after_frame() -> None:
    """The room with a person walking: every step's scene has new arrays (the person moved), lit
    per crossing; a scene drawn twice gets its segments' colours lit once. Both agree with the
    per-pixel reference, frame after frame, as the robot turns."""
    from ninjemys.sim.world2d import MovingObstacle

    world = parse_sdf_world(world_text(*ROOM), "room.world", NO_ENV)
    route = np.array([[-2.0, -1.5], [-2.0, 1.5]])
    world.moving.append(MovingObstacle("person", "cylinder", (0.25, 0.25), 1.7, (200, 120, 60), route, 0.5))
    sim = Simulation(world)
    r = sim.add_robot("pb", load_robot_model("puzzlebot"), 1.0, 0.2, math.pi)
    for i in range(4):
        r.yaw = math.pi + (i - 1.5) * 0.4
        for _ in range(20):
            sim.step()
        assert_matches_reference(sim, r)  # a new scene: lit per crossing
        scene = sim.scene(r.name)
        sim.render(r, scene)
        r.yaw += 0.01  # the same scene again, the camera turned: its palette
        rgb, _ = sim.render(r, scene)
        ref_rgb, _ = reference_render(sim, r)
        assert (rgb != ref_rgb).any(axis=2).sum() < 20
