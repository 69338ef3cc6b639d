"""The introspection server: publish a container tree's structure and live status for smach_viewer.

Every container in the tree gets a proxy that publishes on ``<server_name>/smach/container_structure``
(children and outcome edges) and ``<server_name>/smach/container_status`` (initial and active states,
the pickled userdata), each message naming the container by its path (``/SM_ROOT/SUB``). Status goes
out on every transition and both as a heartbeat every 2 s; ``<server_name>/smach/container_init``
sets a container's initial state and userdata from outside. Same topics and encoding as smach_ros
(userdata: base64 of a protocol-2 pickle), so ROS 1's smach_viewer and ours read either.
"""

from __future__ import annotations

import base64
import pickle
import threading
import time
from typing import Any

import rospy
import rostopic
import smach
from smach_msgs.msg import SmachContainerInitialStatusCmd, SmachContainerStatus, SmachContainerStructure
from std_msgs.msg import Header

__all__ = ["IntrospectionClient", "IntrospectionServer"]

STATUS_TOPIC = "/smach/container_status"
INIT_TOPIC = "/smach/container_init"
STRUCTURE_TOPIC = "/smach/container_structure"


def _pickled(data: dict[str, Any]) -> str:
    try:
        return base64.b64encode(pickle.dumps(data, 2)).decode("utf-8")
    except Exception:  # userdata holding something unpicklable (a lock, a socket) is still introspected
        return base64.b64encode(pickle.dumps({k: repr(v) for k, v in data.items()}, 2)).decode("utf-8")


class IntrospectionClient:
    """Find introspection servers and set a container's initial state remotely."""

    def get_servers(self) -> list[str]:
        topics = rostopic.find_by_type("smach_msgs/SmachContainerStatus")
        return [t[: t.rfind(STATUS_TOPIC)] for t in topics]

    def set_initial_state(
        self,
        server: str,
        path: str,
        initial_states: list[str],
        initial_userdata: smach.UserData | None = None,
        timeout: Any = None,
    ) -> bool | None:
        """Send the command, and with a ``timeout`` wait for a status that confirms it (True/False)."""
        initial_userdata = initial_userdata if initial_userdata is not None else smach.UserData()
        cmd = SmachContainerInitialStatusCmd(
            path=path, initial_states=initial_states, local_data=_pickled(initial_userdata._data)
        )
        seen = threading.Event()
        latest: dict[str, Any] = {}

        def on_status(msg: Any) -> None:
            if msg.path == path:
                latest["msg"] = msg
                seen.set()

        sub = rospy.Subscriber(server + STATUS_TOPIC, SmachContainerStatus, on_status)
        pub = rospy.Publisher(server + INIT_TOPIC, SmachContainerInitialStatusCmd, queue_size=1)
        try:
            pub.publish(cmd)
            if timeout is None:
                return None
            deadline = time.monotonic() + (timeout.to_sec() if hasattr(timeout, "to_sec") else float(timeout))
            while time.monotonic() < deadline:
                pub.publish(cmd)
                seen.clear()
                if seen.wait(min(0.3, max(0.0, deadline - time.monotonic()))) and "msg" in latest:
                    msg = latest["msg"]
                    data = pickle.loads(base64.b64decode(msg.local_data)) if msg.local_data else {}
                    if all(s in msg.initial_states for s in initial_states) and all(
                        k in data and data[k] == v for k, v in initial_userdata._data.items()
                    ):
                        return True
            return False
        finally:
            sub.unregister()
            pub.unregister()


class ContainerProxy:
    """Publishes one container's structure and status and applies init commands addressed to it."""

    def __init__(
        self, server_name: str, container: smach.Container, path: str, update_rate: float = 2.0
    ) -> None:
        self._path = path
        self._container = container
        self._update_rate = update_rate.to_sec() if hasattr(update_rate, "to_sec") else float(update_rate)
        self._status_lock = threading.Lock()
        self._stop = threading.Event()
        self._init_sub = rospy.Subscriber(
            server_name + INIT_TOPIC, SmachContainerInitialStatusCmd, self._init_cmd_cb
        )
        self._structure_pub = rospy.Publisher(
            server_name + STRUCTURE_TOPIC, SmachContainerStructure, queue_size=1
        )
        self._status_pub = rospy.Publisher(server_name + STATUS_TOPIC, SmachContainerStatus, queue_size=1)
        container.register_transition_cb(self._transition_cb)
        container.register_start_cb(self._transition_cb)
        container.register_termination_cb(self._transition_cb)
        self._thread = threading.Thread(
            name=f"{server_name}:{path}:heartbeat", target=self._heartbeat, daemon=True
        )

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()

    def _heartbeat(self) -> None:
        while not self._stop.is_set() and not rospy.is_shutdown():
            self._publish_structure("HEARTBEAT")
            self._publish_status("HEARTBEAT")
            self._stop.wait(self._update_rate)

    def _publish_structure(self, info_str: str = "") -> None:
        edges = self._container.get_internal_edges()
        msg = SmachContainerStructure(
            header=Header(stamp=rospy.Time.now()),
            path=self._path,
            children=list(self._container.get_children()),
            internal_outcomes=[str(o) for o, _, _ in edges],
            outcomes_from=[str(f) for _, f, _ in edges],
            outcomes_to=[str(t) for _, _, t in edges],
            container_outcomes=list(self._container.get_registered_outcomes()),
        )
        try:
            self._structure_pub.publish(msg)
        except Exception:
            if not rospy.is_shutdown():
                rospy.logerr("Publishing SMACH introspection structure message failed.")

    def _publish_status(self, info_str: str = "") -> None:
        with self._status_lock:
            msg = SmachContainerStatus(
                header=Header(stamp=rospy.Time.now()),
                path=self._path,
                initial_states=self._container.get_initial_states(),
                active_states=self._container.get_active_states(),
                local_data=_pickled(dict(self._container.userdata._data)),
                info=info_str,
            )
            try:
                self._status_pub.publish(msg)
            except Exception:
                if not rospy.is_shutdown():
                    rospy.logerr("Publishing SMACH introspection status message failed.")

    def _transition_cb(self, *args: Any, **kwargs: Any) -> None:
        info = f"{args[1:]!s}, {kwargs!s}"
        rospy.logdebug("Transitioning: " + info)
        self._publish_status(info)

    def _init_cmd_cb(self, msg: Any) -> None:
        rospy.logdebug(f"Received init message for path: {msg.path} to {list(msg.initial_states)}")
        if msg.path != self._path:
            return
        children = self._container.get_children()
        if not all(s in children for s in msg.initial_states):
            rospy.logerr(
                f"Attempting to set initial state in container '{self._path}' to '{list(msg.initial_states)}', but "
                f"this container only has states: {list(children)}"
            )
            return
        ud = smach.UserData()
        try:
            data = pickle.loads(base64.b64decode(msg.local_data)) if msg.local_data else {}
        except Exception as exc:
            rospy.logerr(f"{self._path}: container_init local_data is not base64 of a pickled dict: {exc}")
            return
        for key, value in dict(data).items():
            ud[key] = value
        self._container.set_initial_state(list(msg.initial_states), ud)
        self._publish_status("REMOTE_INIT")


class IntrospectionServer:
    """``IntrospectionServer(server_name, root_container, '/SM_ROOT')``; ``start()`` / ``stop()``."""

    def __init__(self, server_name: str, state: smach.Container, path: str) -> None:
        self._proxies: list[ContainerProxy] = []
        self._server_name = server_name
        self._state = state
        self._path = path

    def start(self) -> None:
        self.construct(self._server_name, self._state, self._path)

    def stop(self) -> None:
        for proxy in self._proxies:
            proxy.stop()

    def construct(self, server_name: str, state: smach.Container, path: str) -> None:
        """A proxy for ``state`` and, recursively, for every container inside it."""
        proxy = ContainerProxy(server_name, state, path)
        base = "" if path == "/" else path
        for label, child in state.get_children().items():
            if isinstance(child, smach.Container):
                self.construct(server_name, child, f"{base}/{label}")
        proxy._publish_status("Initial state")
        proxy.start()
        self._proxies.append(proxy)

    def clear(self) -> None:
        self._proxies = []
