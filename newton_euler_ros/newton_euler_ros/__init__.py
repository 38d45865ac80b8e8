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
newton_euler_ros: recursive Newton-Euler inverse dynamics for ROS 2.

The numerical core lives in :mod:`newton_euler_ros.core` and imports
nothing from ROS; the ROS adapters (nodes, message conversion) sit beside
it.
"""
import os
import sys

__version__ = '0.1.0'

# numba caches compiled kernels beside the source by default, which puts
# them in the source tree (or fails in a read-only install).  Unless the
# caller chose a place, keep them (as the Makefile does) in
# the user's cache directory; set before anything imports numba.
os.environ.setdefault('NUMBA_CACHE_DIR', os.path.join(
    os.environ.get('XDG_CACHE_HOME') or os.path.join(
        os.path.expanduser('~'), '.cache'), 'newton_euler_ros', 'numba'))

# numpy's and scipy's OpenBLAS runs every matrix operation on a thread per
# core.  The matrices here are small (at most a few hundred columns), and
# on a machine whose cores are busy (a robot computer running its stack)
# those threads wait on each other: with the other core busy, identifying
# a dual-arm current recording took 509 s with two threads and 23 s with
# one (docs/identification.md).  One thread, unless the caller chose; it
# takes effect only where numpy is not loaded yet (the console scripts,
# ``python -m newton_euler_ros...``), and child processes inherit it.
if 'numpy' not in sys.modules:
    os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')
