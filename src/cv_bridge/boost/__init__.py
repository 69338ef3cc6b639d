"""``cv_bridge.boost``: where ROS 1 keeps the compiled helpers (here :mod:`cv_bridge.boost.cv_bridge_boost`)."""
