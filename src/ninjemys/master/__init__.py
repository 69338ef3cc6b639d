"""The ROS 1 master: registrations, parameter server, their XML-RPC face, and the rosout node.

``store`` and ``params`` are plain, synchronous state machines (no I/O); ``server`` maps the Master and
Parameter Server APIs onto them and hands notifications to ``notify``, which sends them
asynchronously with timeouts. ``client.MasterClient`` is what nodes and tools use to talk to a master;
``graph.GraphSnapshot`` is its getSystemState/getTopicTypes answers indexed once for every reader, and
``graph.ping_node`` is ``rosnode ping``.
"""
