"""``zenoh-bridge-ros1``: one ROS 1 graph's topics and services seen in others over Zenoh.

The command line, the key expressions and the discovery beacons follow eclipse-zenoh's Rust
zenoh-plugin-ros1, so this bridge works beside that one (docs/zenoh.md). Layers: ``keys`` (pure key
layout), ``options`` (command line), ``discovery`` (beacons), ``rosside`` (watching the master,
learning types), ``relays`` (the four kinds of bridge), ``core`` (the reconcile loop), ``main``.
"""
