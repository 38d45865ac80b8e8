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
Simulation on top of the core: scenes and their integration.

``scene`` reads and validates scene files (a robot, the effects present,
a task); ``simulate`` holds :class:`~.simulate.SceneDynamics` (exactly a
scene's effects, the wrench always an argument), the one integrator step
and the builtin offline simulator; ``mujoco_model``, ``mujoco_plant`` and
``mujoco_scene`` the MuJoCo plant; ``run.simulate`` runs a scene in the
engine it names.  Nothing here imports ROS.
"""
