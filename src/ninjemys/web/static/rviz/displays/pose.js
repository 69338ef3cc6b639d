// The Pose display: a PoseStamped as rviz's arrow.

import { fromPose } from "/static/lib/tf.js";
import { setPose, clearGroup, arrowMesh } from "/static/rviz/util.js";
import { Display } from "/static/rviz/display.js";

export class PoseDisplay extends Display {
  onMessage(m) {
    clearGroup(this.group);
    const a = arrowMesh(Number(this.option("Shaft Length", 1)) + Number(this.option("Head Length", 0.3)), Number(this.option("Shaft Radius", 0.05)) * 2, Number(this.option("Head Radius", 0.1)) * 2, Number(this.option("Head Length", 0.3)), this.color, Number(this.option("Alpha", 1)));
    setPose(a, fromPose(m.pose));
    this.group.add(a);
    this.frame = m.header.frame_id;
    this.stamp = m.header.stamp;
  }
}
