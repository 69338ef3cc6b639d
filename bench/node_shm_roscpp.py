"""The roscpp reference for bench/node_shm.py: the same pub/sub roles (1080p, 4K images, 1 MB
PointCloud2; latency, flood and 30 Hz modes) as one C++ program built against Debian's libroscpp-dev."""

from __future__ import annotations

SOURCE = r"""
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <thread>
#include <vector>
using Clock = std::chrono::steady_clock;
static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
static double cpu_s() { timespec ts; clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts); return ts.tv_sec + ts.tv_nsec * 1e-9; }
static double wall() { timespec ts; clock_gettime(CLOCK_REALTIME, &ts); return ts.tv_sec + ts.tv_nsec * 1e-9; }
static std::vector<double> lat; static std::vector<std::pair<double, size_t>> arr; static double cpu0 = -1;
static Clock::time_point t0 = Clock::now(); static std::string mode;
template <class M> static void on(const typename M::ConstPtr& m) {
  if (mode == "latency") { lat.push_back(wall() - m->header.stamp.toSec()); return; }
  arr.push_back({since(t0), m->data.size()}); if (arr.size() == 1) cpu0 = cpu_s();
}
template <class M> static void publish(ros::NodeHandle& nh, M& msg, int n) {
  ros::Publisher p = nh.advertise<M>("/big", 1);
  for (int i = 0; i < 3000 && p.getNumSubscribers() < 1; i++) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  double c = cpu_s(); auto start = Clock::now();
  if (mode == "latency") {
    for (int i = 0; i < n; i++) { msg.header.stamp = ros::Time(wall()); p.publish(msg); std::this_thread::sleep_for(std::chrono::milliseconds(50)); }
  } else if (mode == "rate30") {
    for (int i = 1; since(start) < n; i++) { p.publish(msg); double d = i / 30.0 - since(start); if (d > 0) std::this_thread::sleep_for(std::chrono::duration<double>(d)); }
  } else {
    // roscpp's publish only queues: keep its queue (1) from dropping by waiting for the socket to drain is not
    // possible through the API, so flood like a camera driver does: publish as fast as the loop goes
    while (since(start) < n) { p.publish(msg); std::this_thread::sleep_for(std::chrono::microseconds(100)); }
  }
  std::printf("{\"cpu_s\": %f, \"wall_s\": %f}\n", cpu_s() - c, since(start)); std::fflush(stdout);
  std::this_thread::sleep_for(std::chrono::seconds(2));
}
int main(int argc, char** argv) {
  std::string side = argv[1], kind = argv[2]; mode = argv[3]; int n = std::stoi(argv[4]);
  ros::init(argc, argv, side == "pub" ? "shm_pub" : "shm_sub", ros::init_options::AnonymousName);
  ros::NodeHandle nh; ros::AsyncSpinner spinner(1); spinner.start();
  if (side == "pub") {
    if (kind == "cloud") {
      sensor_msgs::PointCloud2 m; m.height = 1; m.width = (1 << 20) / 16; m.point_step = 16; m.row_step = 1 << 20;
      m.data.resize(1 << 20); for (size_t i = 0; i < m.data.size(); i++) m.data[i] = i & 255; publish(nh, m, n);
    } else {
      sensor_msgs::Image m; m.width = kind == "uhd" ? 3840 : 1920; m.height = kind == "uhd" ? 2160 : 1080;
      m.encoding = "rgb8"; m.step = m.width * 3; m.data.resize(m.step * m.height);
      for (size_t i = 0; i < m.data.size(); i++) m.data[i] = i & 255; publish(nh, m, n);
    }
    return 0;
  }
  ros::Subscriber s = kind == "cloud"
      ? nh.subscribe<sensor_msgs::PointCloud2>("/big", 1000, on<sensor_msgs::PointCloud2>, ros::TransportHints().tcpNoDelay())
      : nh.subscribe<sensor_msgs::Image>("/big", 1000, on<sensor_msgs::Image>, ros::TransportHints().tcpNoDelay());
  std::printf("ready\n"); std::fflush(stdout);
  for (int i = 0; i < 12000 && lat.empty() && arr.empty(); i++) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::duration<double>(mode == "latency" ? n * 0.05 + 2 : n + 2));
  if (mode == "latency") {
    std::sort(lat.begin(), lat.end());
    std::printf("{\"latency_ms\": %f, \"n\": %zu}\n", lat.empty() ? 0.0 : lat[lat.size() / 2] * 1e3, lat.size());
  } else {
    double span = arr.size() > 1 ? arr.back().first - arr.front().first : 0; double bytes = 0;
    for (size_t i = 1; i < arr.size(); i++) bytes += arr[i].second;
    std::printf("{\"n\": %zu, \"per_s\": %f, \"gb_per_s\": %f, \"cpu_s\": %f, \"span_s\": %f}\n", arr.size(),
                span > 0 ? (arr.size() - 1) / span : 0.0, span > 0 ? bytes / span / 1e9 : 0.0, cpu_s() - cpu0, span);
  }
  std::fflush(stdout);
  return 0;
}
"""


def binary() -> str | None:
    """Path of the built program, or None when no C++ toolchain / roscpp is installed."""
    from node_common import cpp_program  # node_common imports this module: looked up at call time

    return cpp_program("shm-roscpp", SOURCE)
