"""The browser's tf buffer (static/lib/tf.js) under Node.js: chains through the tree, interpolation at
a stamp, the latest at stamp 0, and rviz's wording when frames are not connected."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

NODE = shutil.which("node")
LIB = Path(__file__).parents[2] / "src/ninjemys/web/static/lib/tf.js"

pytestmark = pytest.mark.skipif(NODE is None, reason="Node.js is not installed")

SCRIPT = """
const { TfBuffer, yawOf } = await import(process.argv[1]);
globalThis.performance ??= { now: () => Date.now() };
const tf = new TfBuffer();
const ts = (parent, child, secs, x, yaw) => ({
  header: { frame_id: parent, stamp: { secs, nsecs: 0 } }, child_frame_id: child,
  transform: { translation: { x, y: 0, z: 0 }, rotation: { x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) } },
});
tf.add({ transforms: [ts("/map", "odom", 0, 1, 0)] }, true);
tf.add({ transforms: [ts("odom", "base_link", 10, 0, 0)] });
tf.add({ transforms: [ts("odom", "base_link", 12, 2, Math.PI / 2)] });
tf.add({ transforms: [ts("base_link", "laser", 0, 0.5, 0)] }, true);
tf.add({ transforms: [ts("elsewhere", "lost", 0, 0, 0)] }, true);
const r = (T) => T && [...T.t.map((v) => Math.round(v * 1000) / 1000), Math.round(yawOf(T.q) * 1000) / 1000];
console.log(JSON.stringify({
  latest: r(tf.lookup("map", "laser")),
  mid: r(tf.lookup("map", "laser", { secs: 11, nsecs: 0 })),
  before: r(tf.lookup("map", "laser", 5)),
  after: r(tf.lookup("map", "laser", 99)),
  inverse: r(tf.lookup("laser", "map")),
  lost: tf.lookup("map", "lost"),
  missing: TfBuffer.missing("/lost", "map"),
  frames: tf.frameNames(),
}));
"""


def test_tf_buffer_chains_interpolates_and_names_missing_frames() -> None:
    proc = subprocess.run(
        [NODE, "--input-type=module", "-e", SCRIPT, LIB.as_uri()], capture_output=True, text=True, timeout=30
    )
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["latest"] == [
        3.0,
        0.5,
        0.0,
        1.571,
    ]  # map->odom (1,0) + odom->base (2,0, 90°) + laser 0.5 ahead
    assert out["mid"] == [2.354, 0.354, 0.0, 0.785]  # halfway in time: (1,0) + (1,0, 45°) + 0.5 at 45°
    assert out["before"] == [1.5, 0.0, 0.0, 0.0]  # older than the history: the oldest
    assert out["after"] == out["latest"]  # newer: the newest, not an extrapolation
    assert out["inverse"] == [-0.5, 3.0, 0.0, -1.571]
    assert out["lost"] is None
    assert out["missing"] == "No transform from [lost] to [map]"
    assert out["frames"] == ["base_link", "elsewhere", "laser", "lost", "map", "odom"]
