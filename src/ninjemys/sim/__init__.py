"""The simulators: ROS turtlesim and the PuzzleBot world (a Gazebo-like 2-D differential-drive sim).

Pure cores (:mod:`~ninjemys.sim.world` for turtlesim, :mod:`~ninjemys.sim.simcore` with
:mod:`~ninjemys.sim.world2d`, :mod:`~ninjemys.sim.raycast`, :mod:`~ninjemys.sim.sensors` and :mod:`~ninjemys.sim.camera` for the
PuzzleBot) carry no ROS; :mod:`~ninjemys.sim.turtlesim_node` and :mod:`~ninjemys.sim.puzzlebot_node`
bind them to topics and services. The simulators know nothing of browsers: their views live in
:mod:`ninjemys.web` and are passed in (``main(argv, view=...)``) by the commands that show them. sim
and :mod:`ninjemys.nav` are peers and do not import each other; maps come from :mod:`ninjemys.maps`.
See docs/sim.md and docs/architecture.md.
"""
