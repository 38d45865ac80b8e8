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
Simulate a scene in the engine it asks for.

``engine: builtin`` (the default) runs :func:`.simulate.simulate_builtin`,
which pays only for the scene's effects; ``engine: mujoco`` runs
:func:`.mujoco_scene.simulate_mujoco`, full physics in MuJoCo.  This
module sits above both, so that the two engines import in one direction
(``mujoco_scene`` takes its dynamics, controller and result from
``simulate``, which knows nothing of MuJoCo).
"""
from .mujoco_scene import simulate_mujoco
from .simulate import check_feedforward_at, simulate_builtin


def simulate(scene, duration=None, controller=None, feedforward=None,
             integrator=None, step=None, progress=False,
             feedforward_at='desired'):
    """
    Simulate a scene deterministically; return a SimulationResult.

    ``controller(t, q, qd) -> (tau, tau_ff)`` defaults to the scene's PD
    plus the library's feedforward (``feedforward``: None for the
    scene's choice, False for none; ``feedforward_at``, 'desired' or
    'measured'); torques are held constant over each step, as a digital
    controller would.  ``integrator`` and ``progress`` (a progress bar)
    apply to the builtin engine; MuJoCo integrates with its own.
    """
    check_feedforward_at(feedforward_at)
    if scene.engine == 'mujoco':
        return simulate_mujoco(scene, duration, controller, feedforward,
                               step, feedforward_at)
    return simulate_builtin(scene, duration, controller, feedforward,
                            integrator, step, progress, feedforward_at)
