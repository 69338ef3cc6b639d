"""The roscpp reference for the node benchmarks: one C++ program with the same roles as node_roles.py
(pong/ping, flood/sink, trigger_server/trigger_client), built once against Debian's libroscpp-dev."""

from __future__ import annotations

SOURCE = r"""
#include <ros/ros.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>
using Clock = std::chrono::steady_clock;
static double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0; std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, (size_t)(q * v.size()))];
}
static std::mutex mu; static std::condition_variable cv; static bool got = false;
int main(int argc, char** argv) {
  std::string role = argv[1];
  ros::init(argc, argv, role, ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  if (role == "pong") {
    ros::Publisher pub = nh.advertise<std_msgs::String>("/pong", 10);
    boost::function<void(const std_msgs::String::ConstPtr&)> cb = [&](const std_msgs::String::ConstPtr& m) { pub.publish(*m); };
    ros::Subscriber sub = nh.subscribe<std_msgs::String>("/ping", 10, cb, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    ros::spin();
  } else if (role == "ping") {
    int count = std::stoi(argv[2]);
    ros::AsyncSpinner spinner(1); spinner.start();
    boost::function<void(const std_msgs::String::ConstPtr&)> cb = [&](const std_msgs::String::ConstPtr&) {
      std::lock_guard<std::mutex> l(mu); got = true; cv.notify_one(); };
    ros::Subscriber sub = nh.subscribe<std_msgs::String>("/pong", 10, cb, ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    ros::Publisher pub = nh.advertise<std_msgs::String>("/ping", 10);
    while (pub.getNumSubscribers() < 1) ros::Duration(0.01).sleep();
    std_msgs::String msg; msg.data = std::string(64, 'x');
    auto wait = [&](double s) { std::unique_lock<std::mutex> l(mu);
      return cv.wait_for(l, std::chrono::duration<double>(s), [] { return got; }); };
    for (int i = 0; i < 200; i++) { { std::lock_guard<std::mutex> l(mu); got = false; } pub.publish(msg); if (wait(0.2)) break; }
    std::vector<double> rtts;
    for (int i = 0; i < count + 200; i++) {
      { std::lock_guard<std::mutex> l(mu); got = false; }
      auto t0 = Clock::now(); pub.publish(msg);
      if (!wait(2.0)) continue;
      if (i >= 200) rtts.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    }
    std::printf("{\"p50_us\": %f, \"p99_us\": %f, \"n\": %zu}\n", pct(rtts, 0.5) * 1e6, pct(rtts, 0.99) * 1e6, rtts.size());
    std::fflush(stdout);
  } else if (role == "trigger_server") {
    boost::function<bool(std_srvs::Trigger::Request&, std_srvs::Trigger::Response&)> h =
      [](std_srvs::Trigger::Request&, std_srvs::Trigger::Response& r) { r.success = true; r.message = "ok"; return true; };
    ros::ServiceServer s = nh.advertiseService("/bench_trigger", h);
    std::printf("ready\n"); std::fflush(stdout);
    ros::spin();
  } else if (role == "trigger_client") {
    int count = std::stoi(argv[2]);
    ros::service::waitForService("/bench_trigger", 20000);
    ros::ServiceClient c = nh.serviceClient<std_srvs::Trigger>("/bench_trigger", true);
    std_srvs::Trigger t;
    for (int i = 0; i < 200; i++) c.call(t);
    std::vector<double> rtts;
    for (int i = 0; i < count; i++) { auto t0 = Clock::now(); c.call(t);
      rtts.push_back(std::chrono::duration<double>(Clock::now() - t0).count()); }
    std::printf("{\"p50_us\": %f, \"p99_us\": %f}\n", pct(rtts, 0.5) * 1e6, pct(rtts, 0.99) * 1e6);
    std::fflush(stdout);
  }
  return 0;
}
"""


def binary() -> str | None:
    """Path of the built program, or None when no C++ toolchain / roscpp is installed."""
    from node_common import cpp_program  # node_common imports this module: looked up at call time

    return cpp_program("roscpp", SOURCE)
