"""smach's core: hierarchical state machines for robot tasks (states, userdata, containers).

Pure Python with no ROS inside: the ``smach`` facade re-exports this, and ``smach_ros`` adds the
states that talk to ROS (actions, services, topics) and the introspection server. Names, signatures,
outcomes, error classes and log lines follow executive_smach 2.5 (Noetic) so course code runs
unchanged. Modules: ``log`` (replaceable loggers and the shutdown check), ``errors``, ``state``
(State, CBState, cb_interface), ``userdata`` (UserData, Remapper), ``container`` (the construction
stack and callbacks), ``state_machine``, ``sequence``, ``concurrence``, ``iterator``.
"""
