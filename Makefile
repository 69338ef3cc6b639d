# ninjemys — set-up, tests and demo. `make test` and `make demo` work from a fresh clone.
# The venv's interpreter: Debian's /usr/bin/python3 when it is >= 3.11 (the same interpreter build real
# ROS 1 runs on, so benchmarks compare like with like), else the first python3 on PATH.
PYTHON ?= $(shell /usr/bin/python3 -c 'import sys, venv, ensurepip; sys.exit(sys.version_info < (3, 11))' 2>/dev/null && echo /usr/bin/python3 || echo python3)
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

# Debian's real ROS 1 (Noetic-era 1.15), used as the reference in interop and comparison tests.
ROS1_DEBS := ros-core python3-rospy python3-rosbag python3-genpy python3-rosmsg python3-roslaunch \
	python3-rostopic python3-rosnode python3-rosparam python3-rosservice python3-rosmaster rosout \
	python3-std-msgs python3-std-srvs python3-geometry-msgs python3-sensor-msgs python3-nav-msgs \
	python3-rosgraph-msgs python3-actionlib-msgs python3-actionlib python3-tf2-msgs \
	python3-diagnostic-msgs python3-visualization-msgs python3-trajectory-msgs python3-shape-msgs \
	python3-stereo-msgs python3-roscpp-msg libroscpp-dev libstd-srvs-dev ros-std-srvs catkin g++ \
	python3-tf2-ros python3-tf python3-tf2-geometry-msgs python3-dynamic-reconfigure \
	python3-message-filters python3-move-base-msgs python3-map-msgs python3-laser-geometry \
	python3-cv-bridge libdynamic-reconfigure-config-init-mutex-dev
# robot descriptions: Debian's C++ robot_state_publisher and urdfdom's check_urdf, the references
ROS1_DEBS += ros-robot-state-publisher liburdfdom-tools
# PyKDL, tf_conversions and joint_state_publisher: the references for ours
ROS1_DEBS += python3-pykdl python3-tf-conversions joint-state-publisher
# C++ nodes through catkin's CMake: the build tool, gencpp and std_msgs' .msg files for C++ messages
ROS1_DEBS += cmake python3-gencpp ros-std-msgs libstd-msgs-dev
# vision: Debian's OpenCV under /usr/bin/python3 and its C++ image_transport republish (side-by-side tests)
ROS1_DEBS += python3-opencv image-transport-tools
# the long tail (issue 21 item 7): Debian's python3-angles, the reference for ours
ROS1_DEBS += python3-angles
# rostest: Debian's rostest, the reference for ours (tests/rostest)
ROS1_DEBS += python3-rostest
# C++ packages with .action files (the books' C++ action servers): actionlib_msgs' .msg definitions
ROS1_DEBS += ros-actionlib-msgs
# interactive_markers' Python server and menu (course code): Debian's, the reference for ours (tests/markers)
ROS1_DEBS += python3-interactive-markers
# catkin_add_nosetests: Debian's nose, which Debian's catkin_make run_tests runs (the reference for ours)
ROS1_DEBS += python3-nose
# tf's C++ library (the navigation tutorials' robot_setup_tf/odometry_publisher, turtle_tf): C++ nodes on tf build
ROS1_DEBS += libtf-dev
# image_geometry's camera models (vision course code): Debian's, the reference for ours (tests/image_geometry)
ROS1_DEBS += python3-image-geometry
# diagnostic_updater (drivers' and nodes' /diagnostics): Debian's, the reference for ours (tests/diagnostic_updater)
ROS1_DEBS += python3-diagnostic-updater
BROWSER_DEBS := chromium chromium-driver fonts-dejavu-core
# multi-host tests: network namespaces (iproute2), roslaunch <machine> over ssh (openssh-server)
NET_DEBS     := iproute2 openssh-server openssh-client
SYSTEM_DEBS  := $(ROS1_DEBS) $(BROWSER_DEBS) $(NET_DEBS) tmux

# npm packages the tests run with Node.js (Foxglove's own WebSocket client), in a git-ignored directory.
NPM_DIR   := .cache/npm
NPM_STAMP := $(NPM_DIR)/node_modules/.installed

.PHONY: all venv system npm lint format typecheck bytecode test test-fast demo bench fuzz soak clean

all: venv

$(STAMP): pyproject.toml
	$(PYTHON) -m venv --clear $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	touch $(STAMP)

venv: $(STAMP)

# Installs the Debian packages the tests compare against (root or sudo needed; skipped when present),
# and Node.js with npm for the Foxglove client tests when no node/npm is on PATH (any build will do).
system:
	@missing=""; for p in $(SYSTEM_DEBS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	command -v node >/dev/null 2>&1 || missing="$$missing nodejs"; \
	command -v npm >/dev/null 2>&1 || missing="$$missing npm"; \
	if [ -n "$$missing" ]; then \
		echo "installing Debian packages:$$missing"; \
		SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
		$$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

$(NPM_STAMP): tests/bridge/js/package.json tests/bridge/js/package-lock.json
	@if command -v npm >/dev/null 2>&1; then \
		mkdir -p $(NPM_DIR) && cp tests/bridge/js/package.json tests/bridge/js/package-lock.json $(NPM_DIR)/ && \
		cd $(NPM_DIR) && npm ci --no-audit --no-fund --loglevel=error && touch node_modules/.installed; \
	else echo "npm not found: the Foxglove client tests will skip"; fi

npm: $(NPM_STAMP)

lint: venv
	$(VENV)/bin/ruff format --check src tests bench examples
	$(VENV)/bin/ruff check --no-cache src tests bench examples

format: venv
	$(VENV)/bin/ruff format src tests bench examples
	$(VENV)/bin/ruff check --fix src tests bench examples

# Static types of the whole of src/ninjemys (strict, no module relaxed); the configuration is in pyproject.toml.
typecheck: venv
	$(VENV)/bin/mypy

# --dist loadfile: each test file runs on one worker, in order (the navigation sessions of
# tests/nav/test_nav_stack.py run one at a time, and the office session's tests follow its goals run).
# --durations: the slowest tests are listed at the end, so a CI log shows what eats the 20-minute budget.
# --no-loadscope-reorder: tests/conftest.py orders the files (the long navigation sessions first).
test: venv system npm lint typecheck bytecode
	$(VENV)/bin/pytest -n 2 -q --dist loadfile --no-loadscope-reorder --durations=25

test-fast: venv bytecode
	$(VENV)/bin/pytest -n 2 -q -m "not ros1 and not browser and not slow"

# ninjemys compiled once: under PYTHONDONTWRITEBYTECODE every process a test starts (roscore, nodes,
# commands: thousands) compiled the modules it imports again, a third of a command's start-up CPU.
bytecode: venv
	$(PY) -m compileall -q -j 0 src

demo: venv
	$(PY) -m ninjemys.demo

bench: venv system
	$(PY) bench/run_all.py

# every parser of untrusted input, 100,000 mutated inputs each (make test runs 2,000: tests/fuzz)
fuzz: venv
	$(PY) tests/fuzz/run_fuzz.py --count 100000

# the soak: 50 nodes under load, random SIGKILLs, two master restarts, a bag throughout, then a cut
# link 20 times (network namespaces, as root); prints heal times p50/p95 and resources start vs end.
# make test runs a ~70 s form (tests/soak/test_soak.py). SOAK_DURATION=seconds of faults.
SOAK_DURATION ?= 600
soak: venv
	$(PY) tests/soak/soak.py --duration $(SOAK_DURATION) --json soak-report.json

clean:
	rm -rf $(VENV) build dist src/*.egg-info .pytest_cache .ruff_cache $(NPM_DIR)
