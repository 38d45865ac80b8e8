# newton_euler_ros: one-command set-up, tests, demo and benchmark.
#   make setup   create/refresh .venv (idempotent; < 2 s when up to date)
#   make test    set up if needed, then run pytest over newton_euler_ros/test
#                and tools/test (pytest.ini)
#   make demo    closed-loop ROS 2 demo of the default scene; report in out/demo/
#   make demo-pick  trajectory efforts + a payload picked up; out/demo_pick/
#   make demo-identify  excite, record, identify, payload, over DDS on a
#                Panda simulated by MuJoCo (a few minutes); out/demo_identify/
#   make demo-identify-mujoco  the same loop offline on a Panda simulated by
#                MuJoCo (about a minute); out/mujoco_identify/
#   make bench   run the benchmarks (peers side by side; cost per effect;
#                regressor, observer, identification time and memory)
#   make bench-identify  identification time and memory (1 and 30 min bags)
#   make peers   add Pinocchio + Robotics Toolbox (reference implementations)
#   make accuracy  accuracy-vs-time report -> docs/accuracy-vs-time.md (+ peers)
#   make accuracy-quick  the same in under a minute, into build/accuracy-quick
#   make colcon-check  build both packages as a ROS 2 workspace with colcon
#   make clean   remove build/, .venv and the stamps in it
# Extra pytest arguments: make test PYTEST_ARGS='-k rnea -x'

SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := test

VENV := .venv
PY   := $(VENV)/bin/python
PYTEST_ARGS ?=
# Two test processes, one test file each at a time (pytest-xdist), in the
# order conftest.py gives (the longest files first): the node
# tests mostly wait on DDS; make test PYTEST_WORKERS= runs them in one.
PYTEST_WORKERS ?= -n 2 --dist loadfile --no-loadscope-reorder

# Tests must not see (or be seen by) ROS 2 nodes on other hosts; override on
# the command line only if you mean it (make test ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET).
export ROS_AUTOMATIC_DISCOVERY_RANGE := LOCALHOST
# Keep rclpy's log files inside the (ignored) build dir, and numba's JIT
# cache where the package keeps it anyway, in the user's cache: a fresh
# clone of the same sources compiles nothing (core/kernels/_jit.py).
export ROS_LOG_DIR := $(CURDIR)/build/ros_log
# Python's bytecode goes to build/pycache, never beside the sources, and is
# written even where PYTHONDONTWRITEBYTECODE is set: without it every
# process (make test starts hundreds: nodes, CLI commands, demos) compiles
# numba, scipy and rclpy from source again, about 1.5 s of CPU each.
unexport PYTHONDONTWRITEBYTECODE
export PYTHONPYCACHEPREFIX := $(CURDIR)/build/pycache
# One BLAS thread per process: the two test workers fill both cores, and
# OpenBLAS threads on a busy core wait on each other (20x slower fits; see
# newton_euler_ros/__init__.py).
export OPENBLAS_NUM_THREADS ?= 1
export NUMBA_CACHE_DIR ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/newton_euler_ros/numba

.PHONY: setup test demo demo-pick demo-identify demo-identify-mujoco bench bench-identify latency \
	peers accuracy \
	accuracy-quick colcon-check clean

setup:
	@bash scripts/setup_env.sh

test: setup
	NEWTON_EULER_NO_SKIPS=1 $(PY) -m pytest -q -p no:cacheprovider --durations=30 $(PYTEST_WORKERS) $(PYTEST_ARGS)

demo: setup
	$(PY) -m newton_euler_tools.demo

demo-pick: setup
	$(PY) -m newton_euler_tools.demo_pick

demo-identify: setup
	$(PY) -m newton_euler_tools.demo_identify

demo-identify-mujoco: setup
	$(PY) -m newton_euler_tools.mujoco_identify

bench: setup
	$(PY) -m newton_euler_tools.bench
	$(PY) -m newton_euler_tools.bench_effects
	$(PY) -m newton_euler_tools.bench_urdf
	$(PY) -m newton_euler_tools.bench_trajectory
	$(PY) -m newton_euler_tools.bench_scaling
	$(PY) -m newton_euler_tools.bench_regressor
	$(PY) -m newton_euler_tools.bench_observer
	$(PY) -m newton_euler_tools.bench_identify
	$(PY) -m newton_euler_tools.bench_mujoco --loop

# identification alone: 40 s recording time; 1 and 30 min time and peak
# memory (about a minute and a half: writing and reading the 30 min bag
# dominates)
bench-identify: setup
	$(PY) -m newton_euler_tools.bench_identify

latency: setup
	$(PY) -m newton_euler_tools.latency_bench

# The full report compares with the peers, so it installs them first.
accuracy: peers
	$(PY) -m newton_euler_tools.accuracy --out docs

accuracy-quick: setup
	$(PY) -m newton_euler_tools.accuracy --quick --out build/accuracy-quick

# Constrained by the main lock so the peers cannot move numpy & co.
peers: setup
	$(PY) -m pip install --progress-bar off -q -c requirements/constraints.txt -r requirements/peers.txt
	$(PY) -c "import pinocchio, roboticstoolbox; print('pinocchio', pinocchio.__version__, '| roboticstoolbox', roboticstoolbox.__version__)"

colcon-check: setup
	bash scripts/colcon_check.sh

clean:
	rm -rf build $(VENV) newton_euler_ros/*.egg-info tools/*.egg-info
