# Copyright 2026 newton_euler_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Compile every kernel into numba's cache ahead of a first start.

The kernels are compiled for types, not for robots: a DH chain and a
small URDF chain with a mimic joint run every entry point a node, the CLI or
the simulator calls on any robot (the dynamics terms, batches, float32,
the regressor and the momentum observer).  Compiled once, a start loads
them from the cache in about a second instead of compiling them for a
minute or two on a 2-core machine (the first start after an install or
an upgrade).

``make setup`` runs it (``python -m newton_euler_ros.precompile``); it
writes a stamp named by the digest of the package's sources into the
cache directory (``NUMBA_CACHE_DIR``, or the user's cache), so a second
run with the same sources and cache returns at once without importing
numba.
"""
import hashlib
import os
import sys
import time

_PACKAGE = os.path.dirname(os.path.abspath(__file__))

# a URDF chain with a mimic joint: what a DH table has not (frames at
# links, a follower joint); the kernels are the same for chains and trees
URDF = """<?xml version="1.0"?>
<robot name="precompile">
  <link name="base"/>
  <link name="torso"><inertial><origin xyz="0 0 0.2"/><mass value="5"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.05" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <link name="finger"><inertial><origin xyz="0 0 0.02"/><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <joint name="lift" type="prismatic"><parent link="base"/>
    <child link="torso"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.3" effort="500" velocity="0.1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="torso"/>
    <child link="arm"/><origin xyz="0 0.2 0.4"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="50" velocity="2"/></joint>
  <joint name="finger_joint" type="revolute"><parent link="arm"/>
    <child link="finger"/><origin xyz="0.2 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
    <mimic joint="shoulder" multiplier="0.5" offset="0"/></joint>
</robot>
"""
# the files whose functions numba compiles (and caches)
COMPILED = ('core/kernels/', 'core/observer/', 'ident/excite.py',
            'ident/signals.py')


def sources_digest():
    """Return the SHA-256 of the package's compiled sources (COMPILED)."""
    digest = hashlib.sha256()
    for top, dirs, files in os.walk(_PACKAGE):
        dirs[:] = sorted(d for d in dirs if d != '__pycache__')
        for name in sorted(files):
            path = os.path.join(top, name)
            rel = os.path.relpath(path, _PACKAGE).replace(os.sep, '/')
            if name.endswith('.py') and rel.startswith(COMPILED):
                digest.update(rel.encode())
                with open(path, 'rb') as fh:
                    digest.update(fh.read())
    return digest.hexdigest()


def cache_dir():
    """Return numba's cache directory (``NUMBA_CACHE_DIR``) or ours."""
    return os.environ.get('NUMBA_CACHE_DIR') or os.path.join(
        os.environ.get('XDG_CACHE_HOME')
        or os.path.join(os.path.expanduser('~'), '.cache'),
        'newton_euler_ros')


def stamp_path(digest=None):
    """Return the stamp file in the cache for these sources."""
    return os.path.join(cache_dir(),
                        f'precompiled-{(digest or sources_digest())[:16]}')


def _exercise(model):
    """Call every compiled path once on ``model``."""
    import numpy as np

    from .core import (coriolis_matrix, coriolis_matrix_batch,
                       Float32Dynamics, forward_dynamics,
                       forward_dynamics_batch,
                       forward_dynamics_derivatives,
                       forward_dynamics_derivatives_batch, gravity_torques,
                       gravity_torques_batch, inverse_dynamics,
                       inverse_dynamics_batch,
                       inverse_dynamics_derivatives,
                       inverse_dynamics_derivatives_batch, jacobian,
                       link_poses,
                       mass_matrix, mass_matrix_batch, MomentumObserver,
                       regressor_batch)
    from .core.observer import (contact_step, external_wrench,
                                initial_contact, initial_state,
                                observer_step)
    n = model.n
    z = np.zeros(n)
    q = np.linspace(0.1, 0.3, n)
    w = np.zeros(6)
    links = {name: w for name in list(model.link_frames)[:1]}
    for frame in ('base', 'end_effector'):
        inverse_dynamics(model, q, z, z, w, frame)
    if links:   # wrenches at links (a model read from a URDF)
        inverse_dynamics(model, q, z, z, links, 'link')
    for method in ('crba', 'newton_euler'):
        mass_matrix(model, q, method=method)
    for method in ('composite', 'newton_euler'):
        coriolis_matrix(model, q, z, method=method)
    gravity_torques(model, q)
    jacobian(model, q)
    link_poses(model, q)
    tau = inverse_dynamics(model, q, z, z)
    for method in ('aba', 'cholesky'):
        forward_dynamics(model, q, z, tau, method=method)
    if links:
        forward_dynamics(model, q, z, tau, links, 'link')
    Q = np.tile(q, (2, 1))
    inverse_dynamics_batch(model, Q, Q, Q)
    mass_matrix_batch(model, Q)
    coriolis_matrix_batch(model, Q, Q)
    gravity_torques_batch(model, Q)
    forward_dynamics_batch(model, Q, Q, Q)
    regressor_batch(model, Q, Q, Q)
    regressor_batch(model, Q, Q, Q, drives=True)
    inverse_dynamics_derivatives(model, q, z, z, w)
    forward_dynamics_derivatives(model, q, z, tau, w)
    inverse_dynamics_derivatives_batch(model, Q, Q, Q)
    forward_dynamics_derivatives_batch(model, Q, Q, Q)
    if links:
        inverse_dynamics_derivatives(model, q, z, z, links, 'link')
        forward_dynamics_derivatives(model, q, z, tau, links, 'link')
    f32 = Float32Dynamics(model)
    f32.inverse_dynamics(q, z, z, w)
    f32.mass_matrix(q)
    f32.coriolis_matrix(q, z)
    f32.forward_dynamics(q, z, tau)
    f32.gravity_torques(q)
    obs = MomentumObserver(model, static_friction=0.5)
    state = initial_state(obs)
    observer_step(obs, state, 0.0, q, z, tau)
    observer_step(obs, state, 1e-3, q, z, tau)
    external_wrench(obs, q, state.r)
    contact_step(obs, initial_contact(obs), state.r, state.allowance, 0.0,
                 q, z)


def precompile(log=print):
    """Compile (or load) every kernel on a chain and a tree; seconds."""
    start = time.monotonic()
    from .core import load_robot, load_urdf
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        models = (load_robot('puma560'), load_urdf(URDF))
    for model in models:
        _exercise(model)
    from .ident.excite import precompile as excite_precompile
    from .ident.signals import precompile as signals_precompile
    excite_precompile()
    signals_precompile()
    return time.monotonic() - start


def main(argv=None):
    """``python -m newton_euler_ros.core.precompile [--force]``."""
    argv = sys.argv[1:] if argv is None else argv
    digest = sources_digest()
    stamp = stamp_path(digest)
    if '--force' not in argv and os.path.exists(stamp):
        return 0
    print("[precompile] compiling the kernels into numba's cache "
          '(once per change of their sources: about 10 min on 2 cores)',
          flush=True)
    seconds = precompile()
    os.makedirs(os.path.dirname(stamp), exist_ok=True)
    with open(stamp, 'w', encoding='utf-8') as fh:
        fh.write(f'{seconds:.1f} s\n')
    print(f'[precompile] done in {seconds:.0f} s; cache {cache_dir()}',
          flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
