"""``MenuHandler``: the context menu of interactive markers, with a callback per entry.

Entries are numbered from 1 in insertion order (the ``id`` rviz sends back in MENU_SELECT feedback);
a sub-entry names its parent's handle. ``apply(server, name)`` writes the visible entries into the
marker (depth first, checkboxes as ``[x] ``/``[ ] `` title prefixes, as ROS 1 shows them) and routes
the marker's MENU_SELECT feedback here; ``reApply`` does it again for every marker after a change.

``from interactive_markers.menu_handler import *`` gives the same names as in ROS 1, so there is no
``__all__``.
"""

import rospy
from visualization_msgs.msg import InteractiveMarkerFeedback, MenuEntry


class EntryContext:
    """One menu entry: what it shows, what it runs and its sub-entries."""

    def __init__(self):
        self.title = ""
        self.command = ""
        self.command_type = 0
        self.sub_entries = []
        self.visible = True
        self.check_state = 0
        self.feedback_cb = None


class MenuHandler:
    """A menu shared by any number of markers of a server."""

    NO_CHECKBOX = 0
    CHECKED = 1
    UNCHECKED = 2

    def __init__(self):
        self.top_level_handles_ = []
        self.entry_contexts_ = {}
        self.current_handle_ = 1
        self.managed_markers_ = set()

    def insert(self, title, parent=None, command_type=MenuEntry.FEEDBACK, command="", callback=None):
        """A new entry (under ``parent``'s handle, else at the top); its handle, or None (with an
        error logged) when the parent does not exist."""
        if parent is not None and parent not in self.entry_contexts_:
            rospy.logerr(f"Parent menu entry {parent} not found.")
            return None
        handle = self.current_handle_
        self.current_handle_ += 1
        entry = EntryContext()
        entry.title, entry.command, entry.command_type, entry.feedback_cb = (
            title,
            command,
            command_type,
            callback,
        )
        self.entry_contexts_[handle] = entry
        if parent is None:
            self.top_level_handles_.append(handle)
        else:
            self.entry_contexts_[parent].sub_entries.append(handle)
        return handle

    def setVisible(self, handle, visible):
        """Show or hide an entry (and so its sub-entries); False if there is no such entry."""
        entry = self.entry_contexts_.get(handle)
        if entry is None:
            return False
        entry.visible = visible
        return True

    def setCheckState(self, handle, check_state):
        """NO_CHECKBOX, CHECKED or UNCHECKED; False if there is no such entry."""
        entry = self.entry_contexts_.get(handle)
        if entry is None:
            return False
        entry.check_state = check_state
        return True

    def getCheckState(self, handle):
        """The entry's check state, None if there is no such entry."""
        entry = self.entry_contexts_.get(handle)
        return None if entry is None else entry.check_state

    def getTitle(self, handle):
        """The entry's title (without a checkbox prefix), None if there is no such entry."""
        entry = self.entry_contexts_.get(handle)
        return None if entry is None else entry.title

    def apply(self, server, marker_name):
        """Put the menu into marker ``marker_name`` of ``server`` (takes effect at the server's
        ``applyChanges()``); False if the server has no such marker."""
        marker = server.get(marker_name)
        if marker is None:
            self.managed_markers_.discard(marker_name)
            return False
        marker.menu_entries = []
        self._push_entries(self.top_level_handles_, marker.menu_entries, 0)
        server.insert(marker, self.processFeedback, InteractiveMarkerFeedback.MENU_SELECT)
        self.managed_markers_.add(marker_name)
        return True

    def reApply(self, server):
        """``apply`` again to every marker this menu was applied to; False if one is gone."""
        results = [self.apply(server, name) for name in sorted(self.managed_markers_)]
        return all(results)

    def processFeedback(self, feedback):
        """MENU_SELECT feedback: the chosen entry's callback."""
        entry = self.entry_contexts_.get(feedback.menu_entry_id)
        if entry is not None and entry.feedback_cb is not None:
            entry.feedback_cb(feedback)

    def _push_entries(self, handles, out, parent_handle):
        for handle in handles:
            entry = self.entry_contexts_[handle]
            if not entry.visible:
                continue
            prefix = {self.CHECKED: "[x] ", self.UNCHECKED: "[ ] "}.get(entry.check_state, "")
            out.append(
                MenuEntry(
                    id=handle,
                    parent_id=parent_handle,
                    title=prefix + entry.title,
                    command=entry.command,
                    command_type=entry.command_type,
                )
            )
            self._push_entries(entry.sub_entries, out, handle)
