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
newton_euler_tools: measuring and reporting tools beside newton_euler_ros.

None of this runs on a robot, so none of it is in the installed ROS
package; colcon skips this folder (``tools/COLCON_IGNORE``) and
``make setup`` installs it, editable, into the project's virtualenv.

- :mod:`.bench`, :mod:`.bench_effects`, :mod:`.bench_urdf`,
  :mod:`.bench_trajectory`: per-call cost (``make bench``); :mod:`.peers`
  builds the same robots in Pinocchio and the Robotics Toolbox;
- :mod:`.latency_bench` with its floor, :mod:`.echo_node`: the node's
  latency over DDS (``make latency``);
- :mod:`.accuracy`: the accuracy-vs-time report (``make accuracy``);
- :mod:`.demo`, :mod:`.demo_pick`: the closed-loop demos (``make demo``,
  ``make demo-pick``), starting nodes through :mod:`.processes`.
"""
