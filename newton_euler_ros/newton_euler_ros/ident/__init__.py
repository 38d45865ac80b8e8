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
Identification of a robot's dynamic parameters from its recordings.

ROS-free (reads rosbag2 files with the ``rosbags`` package) and kept out
of the nodes' runtime path: nothing under ``nodes/`` imports it.  Import
the submodules directly (``ident.bag``, ...); this file imports nothing.
"""
