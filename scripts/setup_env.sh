#!/usr/bin/env bash
# Set the project up from nothing, idempotently:
#
#   1. .venv        python3.11 venv with the pinned requirements (ROS 2 Jazzy
#                   wheels, numpy/numba, pytest, ...), installed by uv from
#                   a wheelhouse (pip where uv cannot be had)
#   2. interfaces   build newton_euler_interfaces with CMake and install it
#                   INTO .venv (the venv is an ament prefix made of wheels)
#   3. package      `pip install -e` newton_euler_ros (edits take effect
#                   without reinstalling) and copy its data files
#                   (config/, launch/, package.xml) to .venv/share/newton_euler_ros
#   4. tools        `pip install -e` tools/ (newton_euler_tools: benchmarks,
#                   accuracy report, demos; not part of the ROS package)
#
# Each step is skipped when a hash of its inputs matches the stamp it wrote
# the last time it succeeded.  Stamps live inside .venv/.setup-stamps, so
# deleting .venv invalidates them all; a step that fails writes no stamp and
# is retried on the next run.  A run with nothing to do takes well under 2 s.
#
# Usage: scripts/setup_env.sh            (normally via `make setup`)
# Env:   PYTHON=/path/to/python3.11      interpreter for the venv
#        WHEELHOUSE=DIR|off              where pinned wheels are kept for fast
#                                        re-creation (default ~/.cache/newton_euler_ros/wheelhouse)
#        IFACE_CACHE=DIR|off             where built newton_euler_interfaces
#                                        installs are kept, by input hash
#                                        (default ~/.cache/newton_euler_ros/interfaces)
#        SETUP_FORCE=1                   ignore the stamps, redo every step
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

VENV="$ROOT/.venv"
BUILD="$ROOT/build"
STAMPS="$VENV/.setup-stamps"
REQ="$ROOT/requirements"
IFACE_SRC="$ROOT/newton_euler_interfaces"
IFACE_BUILD="$BUILD/newton_euler_interfaces"
PKG_SRC="$ROOT/newton_euler_ros"
TOOLS_SRC="$ROOT/tools"
PY_MINOR="3.11"
PY_TUPLE="3, 11"   # same version, as a Python tuple
IFACE_CACHE_ROOT="${IFACE_CACHE:-${XDG_CACHE_HOME:-${HOME:-$ROOT/build}/.cache}/newton_euler_ros/interfaces}"
WHEELHOUSE_ROOT="${WHEELHOUSE:-${XDG_CACHE_HOME:-${HOME:-$ROOT/build}/.cache}/newton_euler_ros/wheelhouse}"

log() { printf '[setup %3ds] %s\n' "$SECONDS" "$*"; }
die() { printf '[setup %3ds] ERROR: %s\n' "$SECONDS" "$*" >&2; exit 1; }
# Run a command, echoing it first so logs show exactly what happened.
run() { printf '[setup] + %s\n' "$*"; "$@"; }
# Same, with its output going to a log file under build/ (shown on failure).
run_logged() {
  local logfile="$1"; shift
  printf '[setup] + %s  > %s\n' "$*" "${logfile#"$ROOT"/}"
  if ! "$@" >"$logfile" 2>&1; then
    tail -40 "$logfile" >&2
    die "failed: $1 ... (full log: ${logfile#"$ROOT"/})"
  fi
}

# pip here is configured with local file:// indexes that do not have most
# packages; it warns about each one.  Drop only those lines, keep the rest
# and pip's exit status.
pip_filtered() {
  printf '[setup] + %s\n' "$*"
  set +e
  "$@" 2>&1 | { grep -v -E "^WARNING: Location 'file://.*' is ignored" || true; }
  local rc=${PIPESTATUS[0]}
  set -e
  return "$rc"
}

# Hash of the given files/dirs (links followed, so a scratch root of links
# to this one, as the docs test makes, hashes the same): paths (relative to the repo, so two clones
# agree) and contents, in a stable order.  Missing paths hash as "missing",
# so creating them later changes the hash.
hash_inputs() {
  local p
  {
    for p in "$@"; do
      p="${p#"$ROOT"/}"
      if [[ -d "$p" ]]; then
        find -L "$p" -type f ! -name '*.pyc' ! -path '*/__pycache__/*' \
          ! -path '*.egg-info/*' -print0 | LC_ALL=C sort -z \
          | xargs -0 -r sha256sum
      elif [[ -f "$p" ]]; then
        sha256sum "$p"
      else
        echo "missing $p"
      fi
    done
  } | sha256sum | cut -d' ' -f1
}

stamp_ok() { [[ -f "$STAMPS/$1" && "$(cat "$STAMPS/$1")" == "$2" ]]; }
stamp_write() { mkdir -p "$STAMPS" && printf '%s\n' "$2" >"$STAMPS/$1"; }

# ---------------------------------------------------------------------------
# Inputs of each step.  A step's hash includes the previous step's, so e.g. a
# new ROS wheel pin rebuilds the interfaces against it.
REQ_FILES=("$REQ/ros.txt" "$REQ/python.txt" "$REQ/colcon.txt" "$REQ/constraints.txt")
H_VENV="$(hash_inputs "${REQ_FILES[@]}" "$ROOT/scripts/setup_env.sh")"
H_IFACE="$(printf '%s %s' "$H_VENV" "$(hash_inputs "$IFACE_SRC")" | sha256sum | cut -d' ' -f1)"
H_PKG="$(printf '%s %s' "$H_VENV" "$(hash_inputs \
  "$PKG_SRC/setup.py" "$PKG_SRC/setup.cfg" "$PKG_SRC/package.xml" \
  "$PKG_SRC/resource" "$PKG_SRC/config" "$PKG_SRC/launch" \
  "$PKG_SRC/newton_euler_ros/__init__.py" \
  "$ROOT/scripts/setup_env.sh")" | sha256sum | cut -d' ' -f1)"
H_TOOLS="$(printf '%s %s' "$H_VENV" "$(hash_inputs \
  "$TOOLS_SRC/pyproject.toml" "$TOOLS_SRC/newton_euler_tools/__init__.py" \
  "$ROOT/scripts/setup_env.sh")" | sha256sum | cut -d' ' -f1)"

if [[ "${SETUP_FORCE:-0}" != 1 && -x "$VENV/bin/python" ]] \
   && stamp_ok venv "$H_VENV" && stamp_ok interfaces "$H_IFACE" \
   && stamp_ok package "$H_PKG" && stamp_ok tools "$H_TOOLS"; then
  log "up to date (.venv; remove it or run 'make clean' to start over)"
  # the kernels' sources may have changed since (an edit, a pull): their
  # compiled cache is stamped by their digest, a no-op when it matches
  "$VENV/bin/python" -m newton_euler_ros.precompile \
    || die "compiling the kernels ahead (python -m newton_euler_ros.precompile) failed"
  exit 0
fi

mkdir -p "$BUILD"
# Two make targets (or two engineers) setting up at once would race on the
# venv and the CMake build dir: serialize them.
exec 9>"$BUILD/.setup.lock"
flock 9

# A sourced ROS 2 installation (/opt/ros/...) would leak its Python 3.12
# packages and its prefixes into our Python 3.11 venv build: isolate.
unset PYTHONPATH PYTHONHOME
if [[ -n "${AMENT_PREFIX_PATH:-}${COLCON_PREFIX_PATH:-}" ]]; then
  log "note: ignoring the sourced ROS environment for this set-up"
fi

# ---------------------------------------------------------------------------
# Step 1: the virtualenv.
find_python() {
  local cand
  for cand in "${PYTHON:-}" "python$PY_MINOR" \
      /root/.pyenv/versions/"$PY_MINOR".*/bin/python"$PY_MINOR" \
      /usr/local/bin/python"$PY_MINOR" /usr/bin/python"$PY_MINOR"; do
    [[ -n "$cand" ]] || continue
    if "$cand" -c "import sys, venv; sys.exit(sys.version_info[:2] != ($PY_TUPLE))" \
        >/dev/null 2>&1; then
      # Resolve pyenv shims etc. to the real interpreter.
      "$cand" -c 'import sys; print(sys.executable)'
      return 0
    fi
  done
  return 1
}

# uv, a pip written in Rust, pinned here rather than in requirements/ (a
# new pin there would re-download the whole wheelhouse); its wheel sits in
# the wheelhouse beside the others.
UV_VERSION="0.13.9"
UV_CACHE="${XDG_CACHE_HOME:-${HOME:-$ROOT/build}/.cache}/newton_euler_ros/uv"

# Install the pinned requirements from wheelhouse $1 with uv; status 1
# (and a note) if uv cannot be had or fails, so that pip takes over.
uv_install() {
  local wh="$1"
  if ! compgen -G "$wh/uv-$UV_VERSION-*.whl" >/dev/null; then
    pip_filtered "$VENV/bin/python" -m pip download --progress-bar off -q \
      --no-deps -d "$wh" "uv==$UV_VERSION" >/dev/null 2>&1 || true
  fi
  if ! pip_filtered "$VENV/bin/python" -m pip install --progress-bar off -q \
      --no-compile --no-index --find-links "$wh" "uv==$UV_VERSION" \
      >/dev/null 2>&1; then
    log "uv $UV_VERSION not in $wh and not downloadable: pip installs instead"
    return 1
  fi
  if ! UV_CACHE_DIR="$UV_CACHE" run "$VENV/bin/uv" pip install -q \
      --link-mode=copy --python "$VENV/bin/python" --no-index \
      --find-links "$wh" "${REQ_ARGS[@]}"; then
    log "uv failed (above): pip installs instead"
    return 1
  fi
}

venv_usable() {
  [[ -x "$VENV/bin/python" ]] && "$VENV/bin/python" -c \
    "import sys, pip; sys.exit(sys.version_info[:2] != ($PY_TUPLE))" >/dev/null 2>&1
}

if [[ "${SETUP_FORCE:-0}" == 1 ]] || ! stamp_ok venv "$H_VENV"; then
  log "step 1/4: virtualenv + pinned requirements"
  if ! venv_usable; then
    PY="$(find_python)" || die "Python $PY_MINOR not found; install it or set PYTHON=/path/to/python$PY_MINOR"
    [[ -e "$VENV" ]] && run rm -rf "$VENV"   # half-created or wrong Python
    run "$PY" -m venv "$VENV"
  fi
  rm -f "$STAMPS"/*   # everything below must be redone against this venv
  for f in "${REQ_FILES[@]}"; do [[ -f "$f" ]] || die "missing $f"; done
  # pip's own cache stays on, but on this network it stores almost nothing
  # (the registry proxy sends no Cache-Control headers, so pip's HTTP cache
  # skips every download).  So all pinned wheels are kept in a wheelhouse
  # keyed on the requirement files: a re-created venv installs from it with
  # no network at all (measured: whole set-up ~36 s instead of ~50 s).
  # WHEELHOUSE=off disables it.
  # --no-compile: byte-compiling ~25k files of wheels doubles the install
  # time; Python writes the .pyc of what is actually imported on first use.
  REQ_ARGS=(-c "$REQ/constraints.txt" -r "$REQ/ros.txt" -r "$REQ/python.txt" -r "$REQ/colcon.txt")
  if [[ "$WHEELHOUSE_ROOT" == off ]]; then
    pip_filtered "$VENV/bin/python" -m pip install --progress-bar off -q --no-compile "${REQ_ARGS[@]}" \
      || die "pip install failed (see above); re-run 'make setup' to retry"
  else
    WH="$WHEELHOUSE_ROOT/$(hash_inputs "${REQ_FILES[@]}" | cut -c1-16)-py$PY_MINOR"
    if [[ ! -f "$WH/.complete" ]]; then
      log "filling wheelhouse $WH"
      mkdir -p "$WH"
      # `pip wheel`, not `pip download`: sdists (empy, flake8-quotes) are
      # built into wheels now, so the offline install needs no build backend.
      pip_filtered "$VENV/bin/python" -m pip wheel --progress-bar off -q \
        -w "$WH" "${REQ_ARGS[@]}" \
        || die "downloading the pinned wheels failed (see above); re-run 'make setup' to retry"
      touch "$WH/.complete"
      # Wheelhouses of older requirement sets are dead weight (~150 MB each).
      find "$WHEELHOUSE_ROOT" -mindepth 1 -maxdepth 1 -type d ! -path "$WH" -exec rm -rf {} +
    fi
    # uv installs the same wheels from the same wheelhouse in 10-15 s,
    # where pip takes 80 s (unpacking 1.8 GB in Python); its cache of
    # unpacked wheels ($UV_CACHE, about 2 GB) is copied from, never linked
    # to (the steps below edit files in the venv).  Without uv's wheel and
    # no network to fetch it, pip as before.
    if uv_install "$WH"; then
      :
    elif ! pip_filtered "$VENV/bin/python" -m pip install --progress-bar off -q --no-compile \
        --no-index --find-links "$WH" "${REQ_ARGS[@]}"; then
      rm -f "$WH/.complete"   # maybe a damaged wheelhouse: refill next time
      die "pip install from $WH failed (see above); re-run 'make setup' to retry"
    fi
  fi

  # The ROS wheels were built under /opt/python/cp311-cp311 (manylinux) and
  # their exported CMake targets still point at that Python's and numpy's
  # include dirs.  Point them at this venv's, or building any message package
  # fails with "Imported target ... includes non-existent path".
  PY_INC="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
  NP_INC="$("$VENV/bin/python" -c 'import numpy; print(numpy.get_include())')"
  [[ -f "$PY_INC/Python.h" ]] || die "Python headers not found at $PY_INC (need the -dev/headers package)"
  mapfile -t stale < <(grep -rl --include='*.cmake' '/opt/python/cp311-cp311' "$VENV/share" || true)
  if ((${#stale[@]})); then
    log "rewriting stale /opt/python include paths in ${#stale[@]} CMake files"
    sed -i \
      -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$NP_INC#g" \
      -e "s#/opt/python/cp311-cp311/include/python3.11#$PY_INC#g" \
      "${stale[@]}"
  fi
  if grep -rq --include='*.cmake' '/opt/python/cp311-cp311' "$VENV/share"; then
    die "unexpected /opt/python paths remain in $VENV/share/**/*.cmake"
  fi

  # ament_index_python (get_package_share_directory) needs AMENT_PREFIX_PATH.
  # Put the venv on it for every Python started from the venv, so nothing
  # has to be sourced.  A .pth line runs at interpreter start-up; it extends
  # (never overwrites) a value that is already set.
  SITE="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
  cat >"$SITE/newton_euler_ros_env.pth" <<'PTH'
import os, sys; _p = [x for x in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if x]; _p[:0] = [] if sys.prefix in _p else [sys.prefix]; os.environ['AMENT_PREFIX_PATH'] = os.pathsep.join(_p)
PTH
  stamp_write venv "$H_VENV"
fi

# Environment for building against the venv as an ament/CMake prefix.
export AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" PATH="$VENV/bin:$PATH"
unset COLCON_PREFIX_PATH

# ---------------------------------------------------------------------------
# Step 2: newton_euler_interfaces -> .venv (lib/, share/, site-packages/).
iface_build() {
  # Fresh build dir each time: no stale generated code from a
  # renamed/removed .srv can survive.
  rm -rf "$IFACE_BUILD"
  run_logged "$BUILD/interfaces-configure.log" cmake -S "$IFACE_SRC" -B "$IFACE_BUILD" \
    -DCMAKE_INSTALL_PREFIX="$VENV" \
    -DCMAKE_BUILD_TYPE=Release \
    -DBUILD_TESTING=OFF \
    -DPython3_EXECUTABLE="$VENV/bin/python"
  run_logged "$BUILD/interfaces-build.log" cmake --build "$IFACE_BUILD" -j "$(nproc)"
  run_logged "$BUILD/interfaces-install.log" cmake --install "$IFACE_BUILD"
}
# The install (27 s of CMake on 2 cores) is kept as a tar of the installed
# files, relative to the prefix, with the prefix they name.  Only text
# files may name it (checked when kept): a clone elsewhere rewrites them.
iface_to_cache() {
  local manifest="$IFACE_BUILD/install_manifest.txt" rel tmp f
  [[ -f "$manifest" ]] || return 0
  rel="$(sed "s|^$VENV/||" "$manifest")"
  while IFS= read -r f; do
    if grep -qF "$VENV" "$VENV/$f" && ! grep -qIF "$VENV" "$VENV/$f"; then
      log "not caching newton_euler_interfaces: $f names $VENV"; return 0
    fi
  done <<<"$rel"
  mkdir -p "$IFACE_CACHE_ROOT" || return 0
  printf '%s\n' "$VENV" >"$BUILD/interfaces-prefix.txt"
  tmp="$(mktemp "$IFACE_CACHE_ROOT/.tmp.XXXXXX")" || return 0
  if tar -cf "$tmp" -C "$BUILD" interfaces-prefix.txt \
      -C "$VENV" $rel 2>/dev/null; then
    mv -f "$tmp" "$IFACE_TAR"
    # keep the four newest
    ls -1t "$IFACE_CACHE_ROOT"/*.tar 2>/dev/null | tail -n +5 | xargs -r rm -f
  else
    rm -f "$tmp"
  fi
}
iface_from_cache() {
  local old f
  mkdir -p "$BUILD"
  tar -xf "$IFACE_TAR" -C "$BUILD" interfaces-prefix.txt 2>/dev/null || return 1
  old="$(cat "$BUILD/interfaces-prefix.txt")"
  [[ -n "$old" ]] || return 1
  tar -xf "$IFACE_TAR" -C "$VENV" --exclude interfaces-prefix.txt || return 1
  rm -f "$VENV/interfaces-prefix.txt"
  if [[ "$old" != "$VENV" ]]; then
    tar -tf "$IFACE_TAR" | grep -v '^interfaces-prefix.txt$' | while IFS= read -r f; do
      if [[ -f "$VENV/$f" ]] && grep -qIF "$old" "$VENV/$f"; then
        sed -i "s|$old|$VENV|g" "$VENV/$f"
      fi
    done
  fi
}
if [[ "${SETUP_FORCE:-0}" == 1 ]] || ! stamp_ok interfaces "$H_IFACE"; then
  log "step 2/4: build + install newton_euler_interfaces into .venv"
  rm -f "$STAMPS/interfaces"   # a failed attempt may leave a half install
  command -v cmake >/dev/null || die "cmake not found (apt-get install cmake)"
  command -v c++ >/dev/null || die "no C++ compiler (apt-get install g++)"
  IFACE_TAR="$IFACE_CACHE_ROOT/$H_IFACE.tar"
  if [[ "${IFACE_CACHE:-}" != off && -f "$IFACE_TAR" ]] && iface_from_cache; then
    log "newton_euler_interfaces from the cache: ${IFACE_TAR#"${HOME:-/nonexistent}"/}"
  else
    iface_build
    [[ "${IFACE_CACHE:-}" == off ]] || iface_to_cache
  fi
  # Import the service AND load its C type support (the .so files in
  # .venv/lib, found through the LD_LIBRARY_PATH the wheel bootstrap sets).
  "$VENV/bin/python" -c '
from newton_euler_interfaces.srv import ComputeDynamics, Linearize
from rclpy.type_support import check_for_type_support
for srv in (ComputeDynamics, Linearize):
    check_for_type_support(srv)
    srv.Request(); srv.Response()
' || { rm -f "$IFACE_TAR"; die "newton_euler_interfaces was installed but does not import/load"; }
  stamp_write interfaces "$H_IFACE"
fi

# ---------------------------------------------------------------------------
# Step 3: newton_euler_ros, editable.
if [[ "${SETUP_FORCE:-0}" == 1 ]] || ! stamp_ok package "$H_PKG"; then
  log "step 3/4: install newton_euler_ros (editable) + data files into .venv"
  rm -f "$STAMPS/package"
  [[ -f "$PKG_SRC/newton_euler_ros/__init__.py" ]] \
    || die "newton_euler_ros/newton_euler_ros/__init__.py is missing"
  # --use-pep517: a PEP 660 editable wheel.  pip then writes the console
  # scripts to .venv/bin (setup.cfg's [develop]/[install] script dirs are
  # for colcon and are not used here).  --no-build-isolation: build with
  # the pinned setuptools/wheel already in the venv, no extra download.
  # editable_mode=compat: a plain path entry (.pth) instead of an import
  # hook, so that from the repository root the regular package wins over
  # the namespace package Python would otherwise make of the
  # newton_euler_ros/ folder in the current directory.
  pip_filtered "$VENV/bin/python" -m pip install --progress-bar off -q \
    --no-deps --no-build-isolation --use-pep517 -e "$PKG_SRC" \
    --config-settings editable_mode=compat \
    || die "pip install -e newton_euler_ros failed"
  # Editable wheels leave setup.py's data_files out.  Install them as colcon
  # would (share/newton_euler_ros/..., ament index marker), taking the list
  # from setup.py itself; old copies go first so removed files disappear.
  rm -rf "$VENV/share/newton_euler_ros"
  (cd "$PKG_SRC" && "$VENV/bin/python" - "$VENV" <<'PY'
import os, shutil, sys, warnings
warnings.simplefilter('ignore')
import setuptools  # noqa: F401  (first, so distutils is setuptools' copy)
from distutils.core import run_setup
prefix = sys.argv[1]
dist = run_setup('setup.py', stop_after='init')
n = 0
for dest, files in dist.data_files or []:
    os.makedirs(os.path.join(prefix, dest), exist_ok=True)
    for f in files:
        shutil.copy2(f, os.path.join(prefix, dest, os.path.basename(f)))
        n += 1
print(f'[setup] copied {n} data files to {prefix}/share')
PY
  ) || die "installing newton_euler_ros data files failed"
  [[ -x "$VENV/bin/newton-euler" ]] || die ".venv/bin/newton-euler was not created"
  "$VENV/bin/python" -c '
import newton_euler_ros
from ament_index_python.packages import get_package_share_directory
get_package_share_directory("newton_euler_ros")
' || die "newton_euler_ros does not import / is not in the ament index"
  stamp_write package "$H_PKG"
fi

# ---------------------------------------------------------------------------
# Step 4: newton_euler_tools (tools/), editable: `python -m
# newton_euler_tools.bench` etc. run from any directory, and edits take
# effect without reinstalling.  Same pip options as step 3.
if [[ "${SETUP_FORCE:-0}" == 1 ]] || ! stamp_ok tools "$H_TOOLS"; then
  log "step 4/4: install newton_euler_tools (editable) into .venv"
  rm -f "$STAMPS/tools"
  [[ -f "$TOOLS_SRC/newton_euler_tools/__init__.py" ]] \
    || die "tools/newton_euler_tools/__init__.py is missing"
  pip_filtered "$VENV/bin/python" -m pip install --progress-bar off -q \
    --no-deps --no-build-isolation --use-pep517 -e "$TOOLS_SRC" \
    --config-settings editable_mode=compat \
    || die "pip install -e tools failed"
  (cd / && "$VENV/bin/python" -c 'import newton_euler_tools') \
    || die "newton_euler_tools does not import"
  stamp_write tools "$H_TOOLS"
fi

# ---------------------------------------------------------------------------
# The kernels compiled into numba's cache once, ahead of any node's first
# start (a minute or more on 2 cores); a stamp named by the compiled
# sources' digest makes this a no-op (0.2 s) until they change.
"$VENV/bin/python" -m newton_euler_ros.precompile \
  || die "compiling the kernels ahead (python -m newton_euler_ros.precompile) failed"

log "done: $("$VENV/bin/python" -c 'import sys; print(sys.executable)'), $(du -sh "$VENV" | cut -f1)"
