#!/usr/bin/env bash
# Check that newton_euler_interfaces + newton_euler_ros build and run as an
# ordinary ROS 2 colcon workspace, the way a user with apt-installed ROS 2
# Jazzy would build them:
#
#   source /opt/ros/jazzy/setup.bash        # here: the .venv ament prefix
#   colcon build [--symlink-install]
#   source install/setup.bash
#
# There is no apt ROS on this machine, so the underlay is the project's
# .venv (ROS 2 Jazzy wheels + colcon from requirements/colcon.txt; run
# `make setup` first).  The workspace is a throwaway copy under
# build/colcon-ws; the source tree is not touched.
#
# Usage: scripts/colcon_check.sh [--symlink-install]   (or: make colcon-check)
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
WS="$ROOT/build/colcon-ws"

log() { printf '[colcon-check] %s\n' "$*"; }
die() { printf '[colcon-check] ERROR: %s\n' "$*" >&2; exit 1; }

[[ -x "$VENV/bin/colcon" ]] || die "$VENV/bin/colcon missing: run 'make setup' first"

# Fresh copies of the two packages (minus build litter) in a new workspace.
rm -rf "$WS"
mkdir -p "$WS/src"
for pkg in newton_euler_interfaces newton_euler_ros; do
  cp -a "$ROOT/$pkg" "$WS/src/$pkg"
  find "$WS/src/$pkg" \( -name '*.egg-info' -o -name __pycache__ -o -name build \) \
    -prune -exec rm -rf {} +
done

# The underlay, as `source /opt/ros/jazzy/setup.bash` would set it up; the
# venv's python3 and colcon come first on PATH.
export AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" PATH="$VENV/bin:$PATH"
unset PYTHONPATH COLCON_PREFIX_PATH
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
export ROS_LOG_DIR="$ROOT/build/ros_log"

# The repository as a user's src/ would hold it: colcon must find the two
# packages and nothing else.  tools/ holds the benchmarks, the report and
# the demos, not robot code; tools/COLCON_IGNORE keeps it out (the colcon
# pinned here does not list a pyproject.toml-only package; other colcon
# extensions may).
[[ -f "$ROOT/tools/COLCON_IGNORE" ]] || die "tools/COLCON_IGNORE missing"
bases=()
for d in "$ROOT"/*/; do
  case "$(basename "$d")" in build|install|log|out) continue ;; esac
  bases+=("$d")
done
found="$(colcon --log-base /dev/null list --names-only --base-paths "${bases[@]}" | sort | xargs)"
[[ "$found" == "newton_euler_interfaces newton_euler_ros" ]] \
  || die "colcon finds '$found' in the repository, expected the two packages (tools/COLCON_IGNORE?)"
log "colcon finds in the repository: $found (tools/ ignored)"

cd "$WS"
cmd=(colcon build "$@" --event-handlers console_cohesion+
     --cmake-args -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$VENV/bin/python")
log "in $WS: ${cmd[*]}"
"${cmd[@]}" >"$WS/colcon-build.log" 2>&1 \
  || { tail -60 "$WS/colcon-build.log" >&2; die "colcon build failed (log: $WS/colcon-build.log)"; }
log "build ok; sourcing install/setup.bash and checking the overlay is used"

# setup.bash reads unset variables: no `set -u` while sourcing it.
set +u
# shellcheck disable=SC1091
source "$WS/install/setup.bash"
set -u

python3 - "$WS/install" <<'PY'
import os, sys
install = sys.argv[1]
import newton_euler_interfaces, newton_euler_ros
from newton_euler_interfaces.srv import ComputeDynamics, Linearize
from rclpy.type_support import check_for_type_support
from ament_index_python.packages import get_package_share_directory
check_for_type_support(ComputeDynamics)
check_for_type_support(Linearize)
share = get_package_share_directory('newton_euler_ros')
for what, path in [('newton_euler_interfaces', newton_euler_interfaces.__file__),
                   ('newton_euler_ros', newton_euler_ros.__file__),
                   ('share/newton_euler_ros', share)]:
    print(f'[colcon-check]   {what}: {path}')
    # --symlink-install points back at the (copied) sources in the workspace
    assert os.path.realpath(path).startswith(os.path.dirname(install)), \
        f'{what} not taken from the workspace'
assert os.path.isdir(os.path.join(share, 'config', 'robots'))
# What runs on a robot only: the tools are not part of the package.
import importlib.util
assert importlib.util.find_spec('newton_euler_ros.bench') is None
assert importlib.util.find_spec('newton_euler_ros.accuracy') is None
# Non-Python files that modules read from beside themselves must be installed.
import glob
src = os.path.join(os.path.dirname(install), 'src', 'newton_euler_ros', 'newton_euler_ros')
pkg = os.path.dirname(newton_euler_ros.__file__)
for f in glob.glob(os.path.join(src, '**', '*.yaml'), recursive=True):
    rel = os.path.relpath(f, src)
    assert os.path.isfile(os.path.join(pkg, rel)), f'{rel} not installed'
    print(f'[colcon-check]   package data: {rel}')
PY

# ros2 run looks for executables in lib/<package>/ (setup.cfg puts them there).
for exe in newton-euler inverse_dynamics_node; do
  [[ -x "$WS/install/newton_euler_ros/lib/newton_euler_ros/$exe" ]] \
    || die "install/newton_euler_ros/lib/newton_euler_ros/$exe missing"
done
"$WS/install/newton_euler_ros/lib/newton_euler_ros/newton-euler" --help >/dev/null \
  || die "newton-euler from the workspace does not run"
log "OK: colcon workspace builds, installs lib/newton_euler_ros/{newton-euler,inverse_dynamics_node} and imports from install/"
