"""The threading model of a ninjemys process, as data: which thread owns each socket, lock and queue.

A node process mixes mechanisms on purpose (see ARCHITECTURE, "Concurrency"): one I/O loop thread
(``ninjemys.net.loop``, no asyncio) for every Node's servers and connection set-up; publishing
threads that write their own bursts; one worker thread per subscription that reads its sockets and
calls back; one blocking thread per service connection. The master and the web tools run asyncio.
The rule that keeps this sane: **nothing touches a socket it does not own**; ownership moves only at
the hand-offs named here (``Runtime.call_soon``/``run``/``start_thread``, ``Subscriber.post``,
``PubConnection`` under its lock).

:data:`THREADS` names every thread started anywhere in ``src/``, the apps' included (its ``threading.Thread`` name) and what runs
on it; :data:`RESOURCES` lists each socket, lock and queue with its owner and who else may touch it,
and how. ``tests/node/test_node_threads.py`` checks the code against both: every thread started in
the core has a row here, every lock/queue attribute of ``ninjemys.node`` and ``ninjemys.net`` has one
(and no row names one that is gone), live nodes run only these threads, and user callbacks run on
the threads this table says. docs/node.md shows the same table.

Nothing imports this module at run time; it is documentation that a test keeps honest.
"""

from __future__ import annotations


class Thread:
    """A kind of thread: ``name`` as ``threading.Thread`` shows it (``<x>`` marks the variable part)."""

    __slots__ = ("name", "started_by", "runs", "user_code")

    def __init__(self, name: str, started_by: str, runs: str, user_code: str = "") -> None:
        self.name = name
        self.started_by = started_by
        self.runs = runs
        #: which user callbacks run here ("" for none: the thread never runs user code)
        self.user_code = user_code

    @property
    def prefix(self) -> str:
        """The fixed start of the name (``sub:`` for ``sub:<topic>``)."""
        return self.name.split("<", 1)[0]


class Resource:
    """A socket, lock or queue: ``where`` is ``module:Class.attribute`` (or a description for sockets)."""

    __slots__ = ("kind", "where", "owner", "others")

    def __init__(self, kind: str, where: str, owner: str, others: str) -> None:
        self.kind = kind
        self.where = where
        self.owner = owner
        #: who else touches it, and how
        self.others = others


LOOP = "ninjemys-io"

THREADS: tuple[Thread, ...] = (
    Thread(
        LOOP,
        "node.runtime.Runtime (first Node of the process; joined when the last one shuts down)",
        "every Node's TCPROS server and slave XML-RPC server, outbound connection set-up "
        "(requestTopic, header exchange), draining publisher queues, the registrar's master link",
    ),
    Thread(
        "ninjemys-io-helper",
        "net.loop.Loop.run_in_thread",
        "one blocking call the loop must not make itself (name resolution), result handed back",
    ),
    Thread(
        "sub:<topic>",
        "node.subscriber.Subscriber (one per Subscriber handle)",
        "the topic's reader (first handle): reads its publisher sockets, cuts frames; every handle: "
        "its queue, deserialization and its callback (a direct=True handle's callback also runs on an "
        "in-process publisher's thread, inside publish, when the handle is idle); on Linux 6.12+ it runs "
        "with a quarter of the scheduler slice (node.slices), so a callback that wakes another thread "
        "keeps the CPU until its next read",
        "subscriber callbacks",
    ),
    Thread(
        "srv:<service>",
        "node.services.ServiceServer.accept (one per client connection)",
        "reads requests, runs the handler, writes responses, until the client leaves",
        "service handlers",
    ),
    Thread(
        "reg:<node>",
        "node.registration.Registrar",
        "the watchdog: checks the master knows the node, re-registers everything after a restart",
    ),
    Thread(
        "timer:<node>",
        "node.node.Node.timer (one per Timer)",
        "waits on the node's clock and calls the timer callback",
        "timer callbacks",
    ),
    Thread(
        "ninjemys-timer",
        "node.timers.Timer made directly on a Clock (rospy.Timer)",
        "waits on the clock and calls the timer callback",
        "timer callbacks",
    ),
    Thread(
        "param-update",
        "node.node.Node.param_update (one per paramUpdate from the master)",
        "runs the subscribed parameter's callbacks",
        "parameter callbacks",
    ),
    Thread(
        "shutdown",
        "node.slave.SlaveApi.shutdown (the master or rosnode kill asks)",
        "Node.shutdown, off the loop (shutdown waits for the loop)",
        "shutdown hooks",
    ),
    Thread(
        "rospy-signal",
        "rospy.client signal handler (Ctrl-C, SIGTERM)",
        "rospy.signal_shutdown, off the interrupted main thread (it may hold locks shutdown needs)",
        "shutdown hooks",
    ),
    Thread(
        "ninjemys-master",
        "master.core.MasterThread (tests, embedded masters; roscore uses its main thread)",
        "the master's asyncio loop: its XML-RPC server and every notification to nodes",
    ),
    Thread(
        "rosout",
        "tools.roscore (starts the rosout node in roscore's process)",
        "creates the rosout Node; the node's own threads do the rest",
    ),
    # -- apps: move_base (nav.move_base_node.MoveBase) --------------------------------------------
    Thread(
        "move_base-control",
        "nav.move_base_node.MoveBase",
        "takes the goal inbox, runs the state machine's cycle at controller_frequency, publishes cmd_vel, "
        "feedback and goal results",
    ),
    Thread(
        "move_base-planner",
        "nav.move_base_node.MoveBase",
        "the global planner: woken by plan_event, plans on a copy of the global costmap",
    ),
    Thread(
        "move_base-costmaps",
        "nav.move_base_node.MoveBase",
        "updates and publishes both costmaps at their update_frequency and publish_frequency",
    ),
    # -- apps: the rest of navigation (nav) ------------------------------------------------------
    Thread(
        "amcl-static-map",
        "nav.amcl_node.AmclNode (use_map_topic false)",
        "calls static_map until the map server answers, then hands the map to the filter; ends",
    ),
    Thread("slam-tf", "nav.slam_node (transform_publish_period > 0)", "publishes map->odom at that period"),
    Thread(
        "safety-loop",
        "nav.safety_node",
        "at the node's rate: decides the command (mux inputs and locks, the scan's zones, e-stop) and publishes cmd_vel",
    ),
    Thread("safety-diagnostics", "nav.safety_node", "publishes /diagnostics every diagnostic period"),
    # -- apps: the simulators (sim) --------------------------------------------------------------
    Thread(
        "puzzlebot-sim",
        "sim.stepper.Stepper (the PuzzleBot simulator node, gzserver, gazebo)",
        "the physics stepper: steps the world at its rate, publishes odometry, tf, scans, IMU, camera and "
        "/clock; the Gazebo services change the world under its lock",
    ),
    Thread(
        "turtlesim-update",
        "sim.turtlesim_node (start)",
        "turtlesim's 16 ms update: moves the turtles, publishes each one's pose and colour sensor",
    ),
    # -- apps: the web gateway (bridge) ----------------------------------------------------------
    Thread(
        "gateway-loop",
        "bridge.server.Gateway.start",
        "the gateway's asyncio loop: HTTP, WebSocket and SSE clients, each client's sender; ROS data "
        "reaches it with call_soon_threadsafe",
    ),
    Thread(
        "gateway-graph",
        "bridge.server.Gateway",
        "polls the master every update_period: channels, services and the connection graph that changed",
    ),
    Thread(
        "gateway_<n>",
        "bridge.server.Gateway.pool (8 workers)",
        "blocking work off the loop: the getBusInfo sweeps of the connection graph, dropping a topic's tap, and rosbridge's call_service",
    ),
    Thread(
        "gateway-call <service>_<n>",
        "bridge.graph (one pool per service, LANE_WORKERS each)",
        "service calls clients asked for, in order per service",
    ),
    Thread(
        "gateway-deadlines", "bridge.graph._Deadlines", "runs callbacks at their deadlines (call timeouts)"
    ),
    Thread(
        "gateway-proxies-close",
        "bridge.graph (shutdown)",
        "closes the service proxies without holding up shutdown; ends",
    ),
    Thread(
        "foxglove-<client>_<n>",
        "bridge.foxglove (one worker per Foxglove client)",
        "that client's requests that block (service calls, parameters), in order",
    ),
    Thread(
        "rosbridge-<client>_<n>",
        "bridge.rosbridge (one worker per rosbridge client)",
        "that client's operations that block (advertise, call_service, parameters), in order",
    ),
    Thread(
        "tf2_web_republisher",
        "bridge.tf_republisher",
        "publishes each client's throttled transforms at its rate",
    ),
    # -- apps: the web tools (web) ---------------------------------------------------------------
    Thread("web-tools", "web.app.WebApp.start", "the web tools' asyncio loop: their HTTP server and pages"),
    Thread("rqt_bag-play", "web.rqt (bag playback)", "publishes the bag's messages at their times and speed"),
    # -- drivers ---------------------------------------------------------------------------------
    Thread(
        "rosserial-call",
        "drivers.rosserial_host (one per service request from the device)",
        "calls the ROS service the device asked for and sends the response back down the link; ends",
    ),
    # -- libraries and commands ------------------------------------------------------------------
    Thread(
        "action-status:<ns>",
        "actionlib.server.ActionServer",
        "publishes the status list at status_frequency and drops finished goals after status_list_timeout",
    ),
    Thread("action-timer:<ns>", "actionlib.server.ActionServer (status_frequency > 0)", "the status timer"),
    Thread(
        "action-execute:<ns>",
        "actionlib.simple_server.SimpleActionServer (with execute_cb)",
        "runs execute_cb for each accepted goal",
        "execute callbacks",
    ),
    Thread(
        "concurrent_split:<label>",
        "smach.concurrence.Concurrence.execute (one per child state, joined before it returns)",
        "runs one child state of the concurrence, as smach's threads of that name do",
        "state execute callbacks",
    ),
    Thread("rosbag-record-writer", "bag.record", "writes the recorded messages to the bag, in order"),
    Thread(
        "rosbag-record-discovery",
        "bag.record (--all, --regex or --node)",
        "polls the master and subscribes to topics that match",
    ),
    Thread("roslaunch", "roslaunch.parent.ROSLaunchParent.start", "the launch's supervisor"),
    Thread("roslaunch-<name>", "roslaunch.scriptapi", "a scripted launch's supervisor"),
    Thread(
        "NodeProcess reader",
        "testing.NodeProcess (two per child: stdout, stderr)",
        "collects the child's output lines for the test",
    ),
    Thread(
        "gzclient-attach",
        "web.gazebo_ros.gzclient_main",
        "waits for gzserver's /gazebo/gui_url parameter, then opens the browser view",
    ),
    Thread(
        "zenoh-beacons",
        "zenoh_bridge.discovery.Beacons",
        "puts an empty beacon for each local resource every period, so remote bridges keep it listed",
    ),
    Thread(
        "zenoh-srv_<n>",
        "zenoh_bridge.core.ZenohBridge._pool (8 workers)",
        "answers queries of bridged services: one ROS service call each, off Zenoh's callback thread",
    ),
)

#: user threads: the caller's own threads (the main thread, publishing threads, service callers)
USER = "user thread"

RESOURCES: tuple[Resource, ...] = (
    # -- sockets ---------------------------------------------------------------------------------
    Resource("socket", "TCPROS listening socket (node.transport.TcprosServer)", LOOP,
             "none: accepted connections are routed by header, then handed over as below"),
    Resource("socket", "slave XML-RPC server and its connections (net.xmlrpc_server)", LOOP, "none"),
    Resource("socket", "publisher -> subscriber stream (node.topics.PubConnection.sock)", USER + " (publishing)",
             "publish writes directly under PubConnection._lock; the loop finishes a burst once the "
             "publisher is idle, drains what the kernel refused, and watches for the peer closing"),
    Resource("socket", "subscriber <- publisher stream (node.subscriber.SubConnection.sock)", "sub:<topic>",
             "the loop connects it and exchanges headers, then hands it to the reader with "
             "Subscriber.post; close() from any thread (idempotent)"),
    Resource("socket", "service server connection (node.services.ServiceServer._serve)", "srv:<service>",
             "the loop accepts it and answers the header; Node shutdown shuts it down to wake the thread"),
    Resource("socket", "service client connection (node.services.ServiceProxy._sock)", USER + " (caller)",
             "one exchange at a time under ServiceProxy._lock; close() from shutdown"),
    Resource("socket", "master XML-RPC client (master.client.MasterClient._sock)", USER + " (caller)",
             "one call at a time under MasterClient._lock (the registrar's probe has its own client)"),
    Resource("socket", "registrar's idle link to the master (node.registration.Registrar._link)", LOOP,
             "opened and watched on the loop; a break sets _link_lost for reg:<node>"),
    Resource("socket", "master XML-RPC server and notifications (master.core, master.notify)",
             "ninjemys-master / roscore's main thread (asyncio)", "none"),
    Resource("socket", "web and bridge servers (web, bridge)", "their asyncio loop thread",
             "ROS data reaches them through Node subscriptions, handed over with call_soon_threadsafe"),
    # -- locks and events --------------------------------------------------------------------------
    Resource("lock", "ninjemys.node.node:Node._lock", "any thread",
             "guards the publication/subscription/service/proxy tables and first-shutdown; held briefly, "
             "never across a master call"),
    Resource("event", "ninjemys.node.node:Node._shutdown_event", "any thread", "set once by shutdown; waited on by spin"),
    Resource("event", "ninjemys.node.node:Node._shutdown_done", "the shutting-down thread",
             "a second shutdown() waits on it"),
    Resource("lock", "ninjemys.node.topics:PubConnection._lock", USER + " (publishing)",
             "the loop takes it to drain or close; serializes writes to the stream"),
    Resource("queue", "ninjemys.node.topics:PubConnection._queue", USER + " (publishing)",
             "frames of a burst and frames the kernel refused; only the refused are bounded by queue_size; drained by the loop, under _lock"),
    Resource("lock", "ninjemys.node.shm_ring:WriterRing._lock", USER + " (publishing)",
             "serializes slot choice, copy and stamp of one SHMROS ring; the loop takes it to close "
             "the ring when the connection ends"),
    Resource("lock", "ninjemys.node.shm_link:ShmPubConnection._ring_lock", USER + " (publishing)",
             "makes and announces the connection's ring once, with the first large message; the loop "
             "takes it to close the ring when the connection ends"),
    Resource("shared memory", "SHMROS ring slots (node.shm_ring)", USER + " (publishing)",
             "the publisher writes a slot and its generation word, the subscriber only the released "
             "word, from whichever thread drops the last view (no lock across processes)"),
    Resource("lock", "ninjemys.node.topics:Publication.lock", USER + " (publishing)",
             "the loop takes it to add a subscriber, so a latched frame is sent either latched or live"),
    Resource("queue", "ninjemys.node.subscriber:Subscriber._queue", "sub:<topic>",
             "the reader appends frames for other handles of the topic, the loop appends latched "
             "replays, an in-process publisher's thread appends its messages (and drops the oldest "
             "beyond its queue_size for an unbounded handle); all through enqueue, then a wake-up; "
             "bounded by queue_size"),
    Resource("lock", "ninjemys.node.subscriber:Subscriber._ops_lock", "sub:<topic>",
             "connection hand-offs (post) from the loop and enqueue from other threads"),
    Resource("lock", "ninjemys.node.subscriber:Subscriber._busy", "sub:<topic>",
             "direct=True handles only: held around each callback of the handle, by its worker (which "
             "pops the queue under it) or by an in-process publisher's thread delivering directly; "
             "unregister takes it to wait for a callback in flight"),
    Resource("lock", "ninjemys.node.subscriber:Subscriber._read_lock", "sub:<topic>",
             "held while the sockets are read and their frames delivered: by the worker, "
             "and by a thread that pulls a lazy handle (its callbacks then run on that thread)"),
    Resource("lock", "ninjemys.node.services:ServiceServer._lock", "srv:<service>",
             "guards the set of open client sockets; the loop adds, shutdown reads"),
    Resource("lock", "ninjemys.node.services:ServiceProxy._lock", USER + " (caller)",
             "one request/response exchange at a time on the proxy's connection"),
    # the rostopic hz/bw/delay windows (ninjemys.node.rates): samples come from a subscription's
    # worker thread, reports from the thread that prints; each window's lock guards its deque
    Resource("lock", "ninjemys.node.rates:RateWindow.lock", "sub:<topic>",
             "the printing thread takes it to copy the gaps for a report"),
    Resource("queue", "ninjemys.node.rates:RateWindow.gaps", "sub:<topic>", "read under RateWindow.lock"),
    Resource("lock", "ninjemys.node.rates:DelayWindow.lock", "sub:<topic>",
             "the printing thread takes it to copy the delays for a report"),
    Resource("queue", "ninjemys.node.rates:DelayWindow.delays", "sub:<topic>", "read under DelayWindow.lock"),
    Resource("lock", "ninjemys.node.rates:BandwidthWindow.lock", "sub:<topic>",
             "the printing thread takes it to copy the samples for a report"),
    Resource("queue", "ninjemys.node.rates:BandwidthWindow.samples", "sub:<topic>",
             "read under BandwidthWindow.lock"),
    Resource("lock", "ninjemys.node.registration:Registrar._lock", "any thread",
             "guards what the node has registered; reg:<node> copies it to re-register"),
    Resource("lock", "ninjemys.node.registration:Turns._cond", "any thread",
             "per-name order of registration calls: a ticket is taken under Node._lock, the master "
             "call waits until the earlier tickets of that name are done; never held across a call"),
    Resource("event", "ninjemys.node.registration:Registrar._stop", "the shutting-down thread",
             "reg:<node> waits on it"),
    Resource("event", "ninjemys.node.registration:Registrar._link_lost", LOOP,
             "set when the master link breaks; reg:<node> waits on it"),
    Resource("lock", "ninjemys.node.clock:Clock._cond", "any thread",
             "simulated time: the /clock callback (sub:/clock) sets the time and notifies; sleepers, "
             "Rates and Timers of that node's clock wait on it"),
    Resource("lock", "ninjemys.node.clock:Clock._lock", "any thread",
             "simulated time: the lock of _cond and of each sleeping thread's own condition (notified "
             "by the /clock callback only when that thread's time has come)"),
    Resource("lock", "ninjemys.node.clock:Clock._gates_lock", "any thread",
             "wall time: guards the set of sleeping threads' gates that wake()/shutdown() open"),
    Resource("lock", "ninjemys.node.clock:Clock._local", "each sleeping thread", "its own gate lock, nobody else's"),
    Resource("event", "ninjemys.node.clock:_MainGate._event", "the main thread (sleeping in wall time)",
             "wake()/shutdown() set it to open the main thread's gate; waited on with interrupt.wait_event"),
    Resource("event", "ninjemys.node.clock:_MainSimWaiter._event", "the main thread (sleeping in sim time)",
             "the /clock callback (sub:/clock) sets it under Clock._lock when the main thread's time has "
             "come; waited on with interrupt.wait_event"),
    Resource("lock", "ninjemys.node.log:NodeLog._lock", "any logging thread", "serializes log-file writes"),
    Resource("lock", "ninjemys.node.log:NodeLog._hold_lock", "any logging thread",
             "messages held until /rosout is attached; attach/detach at start and shutdown"),
    Resource("lock", "ninjemys.node.log:_CallSiteFilter._lock", "any logging thread",
             "throttle/once state per call site"),
    Resource("event", "ninjemys.node.runtime:Runtime._ready", LOOP, "the starting thread waits for the loop"),
    Resource("lock", "ninjemys.node.runtime:_lock", "any thread", "the process's runtime and its user count"),
    Resource("lock", "ninjemys.node.intraprocess:_nodes_lock", "any thread",
             "the process's table of Nodes by slave URI: a Node adds itself at start and leaves at "
             "shutdown; the loop looks a publisher up there before connecting (in-process delivery)"),
    Resource("lock", "ninjemys.net.loop:Loop._wake_lock", "any thread", "call_soon_threadsafe's wake-up pipe write"),
    Resource("queue", "ninjemys.net.loop:Loop._ready", LOOP,
             "other threads append only through call_soon_threadsafe (then a wake-up)"),
    Resource("event", "ninjemys.net.loop:ThreadFuture._event", LOOP, "set with the result; a user thread waits"),
    Resource("lock", "ninjemys.net.loop:_current", "each thread", "thread-local: the loop running on it"),
    Resource("queue", "ninjemys.net.xmlrpc_server:_Connection.queue", LOOP, "none (requests in order)"),
    Resource("queue", "ninjemys.net.xmlrpc_server:_Connection.out", LOOP, "none (response bytes not yet sent)"),
    Resource("lock", "ninjemys.master.client:MasterClient._lock", USER + " (caller)", "one call at a time"),
    Resource("lock", "ninjemys.net.auth:Signer._lock", "any thread checking a signature",
             "held only to remember an accepted nonce and forget expired ones"),
    Resource("lock", "ninjemys.nav.move_base_node:MoveBase.lock", "move_base-control",
             "the planner, costmap and scan threads and the services: the state machine and the costmaps; "
             "the action server's callbacks never take it (they hold the server's lock, which the control "
             "thread takes inside this one)"),
    Resource("lock", "ninjemys.nav.move_base_node:MoveBase.inbox_lock", "move_base-control",
             "the action server's callbacks and the move_base_simple subscriber append goals and cancels"),
    Resource("event", "ninjemys.nav.move_base_node:MoveBase.plan_event", "move_base-planner",
             "set by whichever thread's state-machine step wants a plan"),
)  # fmt: skip
