"""ninjemys: ROS 1 (Noetic) in pure Python, wire-compatible with the real thing.

Nothing is imported here on purpose: `import ninjemys.x` pulls in only what x needs, which keeps
command start-up fast (a `rostopic list` must not pay for numpy or the node runtime).
"""

__version__ = "0.1.0"
ROS_DISTRO = "noetic"
ROS_VERSION = "1.15.15"
