// The index of display classes: rviz's class name -> the module's class. A new display is one module
// in displays/ and one line here (the panel's "Add" list and the .rviz loader read this table).

import { GridDisplay } from "/static/rviz/displays/grid.js";
import { TFDisplay } from "/static/rviz/displays/tf.js";
import { RobotModelDisplay } from "/static/rviz/displays/robot_model.js";
import { LaserScanDisplay } from "/static/rviz/displays/laser_scan.js";
import { PointCloud2Display } from "/static/rviz/displays/point_cloud2.js";
import { MapDisplay } from "/static/rviz/displays/map.js";
import { PathDisplay } from "/static/rviz/displays/path.js";
import { PoseDisplay } from "/static/rviz/displays/pose.js";
import { PoseArrayDisplay } from "/static/rviz/displays/pose_array.js";
import { PoseWithCovarianceDisplay } from "/static/rviz/displays/pose_with_covariance.js";
import { OdometryDisplay } from "/static/rviz/displays/odometry.js";
import { MarkerDisplay } from "/static/rviz/displays/marker.js";
import { ImageDisplay } from "/static/rviz/displays/image.js";
import { PolygonDisplay } from "/static/rviz/displays/polygon.js";

export const DISPLAY_CLASSES = {
  "rviz/Grid": GridDisplay, "rviz/TF": TFDisplay, "rviz/RobotModel": RobotModelDisplay,
  "rviz/LaserScan": LaserScanDisplay, "rviz/PointCloud2": PointCloud2Display, "rviz/Map": MapDisplay,
  "rviz/Path": PathDisplay, "rviz/Pose": PoseDisplay, "rviz/PoseArray": PoseArrayDisplay,
  "rviz/PoseWithCovariance": PoseWithCovarianceDisplay, "rviz/Odometry": OdometryDisplay,
  "rviz/Marker": MarkerDisplay, "rviz/MarkerArray": MarkerDisplay, "rviz/Image": ImageDisplay,
  "rviz/Polygon": PolygonDisplay,
};
