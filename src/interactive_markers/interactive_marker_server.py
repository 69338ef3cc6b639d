"""``InteractiveMarkerServer``: keeps a set of interactive markers and tells clients (rviz) about them.

The protocol is ROS 1's: changes (``insert``, ``setPose``, ``erase``, ``clear``) wait until
``applyChanges()``, which publishes one ``InteractiveMarkerUpdate`` on ``<ns>/update`` and the whole
state as an ``InteractiveMarkerInit`` on the latched ``<ns>/update_full``, both with the server id
(the node name plus ``server_id``) and a sequence number that clients use to spot gaps. An empty
KEEP_ALIVE update goes out every half second. Feedback from clients on ``<ns>/feedback`` moves the
marker (POSE_UPDATE) and calls the marker's callback for that event type, else its default one.

What ROS 1's Python server does is kept where code can see it: ``setPose`` answers False while the
marker's own insertion is still pending, ``get`` shows pending changes, feedback from a second
client within a second of another client's is ignored. Where ROS 1 fails on a plain mistake (a
feedback event for a marker with no callback calls None) this one skips the call.

``from interactive_markers.interactive_marker_server import *`` gives the same names as in ROS 1
(the server, rospy, Header and the InteractiveMarker message classes), so there is no ``__all__``.
"""

import threading
from threading import Lock  # noqa: F401 - a name of ROS 1's module, for `import *`

import rospy
from std_msgs.msg import Header  # noqa: F401 - a name of ROS 1's module, for `import *`
from visualization_msgs.msg import (
    InteractiveMarker,
    InteractiveMarkerFeedback,
    InteractiveMarkerInit,
    InteractiveMarkerPose,
    InteractiveMarkerUpdate,
)

#: how long one client keeps a marker to itself after its last feedback (seconds)
_CLIENT_HOLD = 1.0
_KEEP_ALIVE_PERIOD = 0.5


class MarkerContext:
    """A marker the clients know: its message and callbacks, and which client moved it last."""

    def __init__(self):
        self.last_feedback = rospy.Time.now()
        self.last_client_id = ""
        self.default_feedback_cb = None
        self.feedback_cbs = {}
        self.int_marker = InteractiveMarker()


class UpdateContext:
    """A change waiting for ``applyChanges()``: a whole marker, a new pose, or an erase."""

    FULL_UPDATE = 0
    POSE_UPDATE = 1
    ERASE = 2

    def __init__(self):
        self.update_type = self.FULL_UPDATE
        self.int_marker = InteractiveMarker()
        self.default_feedback_cb = None
        self.feedback_cbs = {}


class InteractiveMarkerServer:
    """The markers of one topic namespace (``topic_ns``), served to every client."""

    DEFAULT_FEEDBACK_CB = 255

    def __init__(self, topic_ns, server_id="", q_size=100):
        self.topic_ns = topic_ns
        self.server_id = rospy.get_name() + server_id
        self.seq_num = 0
        self.mutex = threading.Lock()
        self.marker_contexts = {}
        self.pending_updates = {}
        self.init_pub = rospy.Publisher(
            topic_ns + "/update_full", InteractiveMarkerInit, latch=True, queue_size=100
        )
        self.update_pub = rospy.Publisher(topic_ns + "/update", InteractiveMarkerUpdate, queue_size=100)
        self._feedback_sub = rospy.Subscriber(
            topic_ns + "/feedback", InteractiveMarkerFeedback, self.processFeedback, queue_size=q_size
        )
        self._keep_alive = rospy.Timer(rospy.Duration(_KEEP_ALIVE_PERIOD), self.keepAlive)
        self.publishInit()

    # -- changes, applied by applyChanges() ----------------------------------------------------

    def insert(self, marker, feedback_cb=-1, feedback_type=DEFAULT_FEEDBACK_CB):
        """Add or replace ``marker`` (by name); ``feedback_cb`` (if given) is set at once."""
        with self.mutex:
            update = self.pending_updates.setdefault(marker.name, UpdateContext())
            update.update_type = UpdateContext.FULL_UPDATE
            update.int_marker = marker
        if feedback_cb != -1:
            self.setCallback(marker.name, feedback_cb, feedback_type)

    def setPose(self, name, pose, header=None):
        """Move marker ``name``; an empty ``header.frame_id`` keeps the marker's header. False if
        there is no such marker, or its insertion is still pending (as in ROS 1)."""
        with self.mutex:
            context = self.marker_contexts.get(name)
            update = self.pending_updates.get(name)
            if context is None and update is None:
                return False
            if update is not None and update.update_type == UpdateContext.FULL_UPDATE:
                return False
            if header is None or not header.frame_id:
                header = context.int_marker.header
            self._set_pose(update, name, pose, header)
            return True

    def erase(self, name):
        """Remove marker ``name``; False if there is no such marker, pending or applied."""
        with self.mutex:
            update = self.pending_updates.get(name)
            if update is None:
                if name not in self.marker_contexts:
                    return False
                update = self.pending_updates[name] = UpdateContext()
            update.update_type = UpdateContext.ERASE
            return True

    def clear(self):
        """Remove every marker (pending insertions are dropped)."""
        with self.mutex:
            self.pending_updates = {}
            for name in self.marker_contexts:
                erase = self.pending_updates[name] = UpdateContext()
                erase.update_type = UpdateContext.ERASE

    def setCallback(self, name, feedback_cb, feedback_type=DEFAULT_FEEDBACK_CB):
        """Set (or, with a false ``feedback_cb``, unset) the callback of one event type of marker
        ``name``, or its default callback. Takes effect at once. False if there is no such marker."""
        with self.mutex:
            targets = [
                t for t in (self.marker_contexts.get(name), self.pending_updates.get(name)) if t is not None
            ]
            if not targets:
                return False
            for target in targets:
                if feedback_type == self.DEFAULT_FEEDBACK_CB:
                    target.default_feedback_cb = feedback_cb
                elif feedback_cb:
                    target.feedback_cbs[feedback_type] = feedback_cb
                else:
                    target.feedback_cbs.pop(feedback_type, None)
            return True

    def applyChanges(self):
        """Publish the pending changes as one update, then the whole state on update_full."""
        with self.mutex:
            if not self.pending_updates:
                return
            message = InteractiveMarkerUpdate(type=InteractiveMarkerUpdate.UPDATE)
            pending, self.pending_updates = self.pending_updates, {}
            for name, update in pending.items():
                if update.update_type == UpdateContext.FULL_UPDATE:
                    context = self.marker_contexts.get(name)
                    if context is None:
                        context = self.marker_contexts[name] = MarkerContext()
                        context.default_feedback_cb = update.default_feedback_cb
                        context.feedback_cbs = update.feedback_cbs
                    context.int_marker = update.int_marker
                    message.markers.append(context.int_marker)
                elif update.update_type == UpdateContext.POSE_UPDATE:
                    context = self.marker_contexts.get(name)
                    if context is None:
                        rospy.logerr(f"interactive marker '{name}': pose update for a marker that is gone")
                        continue
                    context.int_marker.pose = update.int_marker.pose
                    context.int_marker.header = update.int_marker.header
                    message.poses.append(
                        InteractiveMarkerPose(
                            header=context.int_marker.header, pose=context.int_marker.pose, name=name
                        )
                    )
                elif self.marker_contexts.pop(name, None) is not None:
                    message.erases.append(name)
            self.seq_num += 1
        self.publish(message)
        self.publishInit()

    # -- queries --------------------------------------------------------------------------------

    def get(self, name):
        """Marker ``name`` as it will be after ``applyChanges()``; None if there is none."""
        with self.mutex:
            update = self.pending_updates.get(name)
            context = self.marker_contexts.get(name)
            if update is None:
                return None if context is None else context.int_marker
            if update.update_type == UpdateContext.FULL_UPDATE:
                return update.int_marker
            if update.update_type == UpdateContext.POSE_UPDATE and context is not None:
                context.int_marker.pose = update.int_marker.pose
                return context.int_marker
            return None

    # -- the topics -----------------------------------------------------------------------------

    def processFeedback(self, feedback):
        """A client's feedback: move the marker on POSE_UPDATE, then call its callback."""
        with self.mutex:
            context = self.marker_contexts.get(feedback.marker_name)
            if context is None:
                return
            now = rospy.Time.now()
            if (
                context.last_client_id != feedback.client_id
                and (now - context.last_feedback).to_sec() < _CLIENT_HOLD
            ):
                rospy.logdebug(
                    f"Rejecting feedback for {feedback.marker_name}: conflicting feedback from separate clients."
                )
                return
            context.last_feedback = now
            context.last_client_id = feedback.client_id
            if feedback.event_type == InteractiveMarkerFeedback.POSE_UPDATE:
                # a marker without a stamp stays in its own frame; else the client's header is taken
                stamped = context.int_marker.header.stamp != rospy.Time()
                header = feedback.header if stamped else context.int_marker.header
                self._set_pose(
                    self.pending_updates.get(feedback.marker_name),
                    feedback.marker_name,
                    feedback.pose,
                    header,
                )
            callback = context.feedback_cbs.get(feedback.event_type, context.default_feedback_cb)
        if callback is not None:
            callback(feedback)

    def keepAlive(self, _event=None):
        """The empty update clients expect every half second."""
        self.publish(InteractiveMarkerUpdate(type=InteractiveMarkerUpdate.KEEP_ALIVE))

    def publish(self, update):
        """Stamp ``update`` with the server id and sequence number and publish it."""
        update.server_id = self.server_id
        update.seq_num = self.seq_num
        self.update_pub.publish(update)

    def publishInit(self):
        """Publish every applied marker on the latched update_full topic."""
        with self.mutex:
            init = InteractiveMarkerInit(
                server_id=self.server_id,
                seq_num=self.seq_num,
                markers=[c.int_marker for c in self.marker_contexts.values()],
            )
        self.init_pub.publish(init)

    def _set_pose(self, update, name, pose, header):
        """Schedule a pose change (the caller holds the mutex). A pending full update takes it as is."""
        if update is None:
            update = self.pending_updates[name] = UpdateContext()
            update.update_type = UpdateContext.POSE_UPDATE
        elif update.update_type != UpdateContext.FULL_UPDATE:
            update.update_type = UpdateContext.POSE_UPDATE
        update.int_marker.pose = pose
        update.int_marker.header = header
