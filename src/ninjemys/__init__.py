"""ninjemys: ROS 1 (Noetic) in pure Python, wire-compatible with the real thing.

Nothing is imported here on purpose: `import ninjemys.x` pulls in only what x needs, which keeps
command start-up fast (a `rostopic list` must not pay for numpy or the node runtime).

The house, bottom up (a floor imports only floors below it; docs/architecture.md and
tests/test_layering.py say the same)::

    base      errors, names, rostime, records, commands, paramyaml, share: leaf modules
    idl       message definitions and classes (and the interface stub packages beside ninjemys)
    packages  ROS packages on disk, manifests, shipped executables
    wire      ROS 1 serialization, TCPROS framing, XML-RPC encoding (sans-IO)
    net       the node's event loop, XML-RPC server and client, addresses
    serve     HTTP and WebSocket on asyncio, for browsers
    master    the master: registrations, parameters, rosout
    node      the client runtime: Node and its parts
    libs      actionlib, tf2, message_filters, dynamic_reconfigure, maps, launch, bag, ...
    compat    the ROS 1 Python facades (rospy, rosbag, tf2_ros, ...) beside ninjemys
    tools     the commands (roscore, rostopic, ...) and ninjemys.testing
    gateway   bridge: rosbridge v2 and Foxglove over WebSocket, the browser's one data path
    sim | nav the simulators | the navigation stack: peers, neither imports the other
    web       the browser apps: rviz, rqt, the graph page, the simulators' views
    apps      the demo and the tutorials
"""

__version__ = "0.1.0"
ROS_DISTRO = "noetic"
ROS_VERSION = "1.15.15"
