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
A scene's ``contacts`` block: the objects of a MuJoCo world.

Read and checked here (no MuJoCo import); :mod:`.mujoco_scene` builds
them.  Lengths in m, forces in N, times in s of simulated time::

    contacts:
      floor: {height: 0.0}                    # the plane z = height
      table: {size: [0.6, 0.8, 0.04], position: [0.6, 0.0, 0.2]}
      pusher:
        link: link6                  # the link it presses
        point: [0.0, 0.0, 0.05]      # where, in the link's frame
        direction: [1.0, 0.0, 0.0]   # the push, in world axes
        schedule: [{t: 1.0, force: 0}, {t: 1.3, force: 20},
                   {t: 1.8, force: 0}]

The table is a box of the given full size centred at ``position`` (world
axes).  The pusher is a 2 cm ball on a rod that follows the point (held
``STANDOFF`` behind it along ``direction``) and presses it with the
schedule's force (piecewise linear; before the first and after the last
time, the last value held); a pad, a 1 cm massless ball at the point, is
what it touches on the link (the two touch nothing else).  Between
pushes it pulls back.
"""
from dataclasses import dataclass

import numpy as np

from ..core.errors import RobotFileError
from ..core.robot_file import _check_keys, _short, to_number, to_vector

STANDOFF = 0.005    # m between the pusher's ball and the pad when idle


@dataclass(frozen=True)
class Pusher:
    """A body that presses ``point`` of ``link`` along ``direction``."""

    link: str
    point: np.ndarray
    direction: np.ndarray
    times: np.ndarray
    forces: np.ndarray

    def force(self, t):
        """Return the commanded push at time t (N, >= 0)."""
        return float(np.interp(t, self.times, self.forces))


@dataclass(frozen=True)
class Contacts:
    """The objects of a MuJoCo scene (None: absent)."""

    floor: object = None        # the floor's height, m
    table: object = None        # (size, position), (3,) arrays
    pusher: Pusher = None


def _mapping(value, where):
    if not isinstance(value, dict):
        raise RobotFileError(f'{where}: must be a mapping, got '
                             f'{_short(value)!r}')
    return value


def read_contacts(block, where):
    """Validate a ``contacts`` block; return :class:`Contacts`."""
    _mapping(block, where)
    _check_keys(block, {'floor', 'table', 'pusher'}, where)
    floor = table = pusher = None
    if block.get('floor') is not None:
        b = _mapping(block['floor'], f'{where}.floor')
        _check_keys(b, {'height'}, f'{where}.floor')
        floor = to_number(b.get('height', 0.0), f'{where}.floor.height')
    if block.get('table') is not None:
        b = _mapping(block['table'], f'{where}.table')
        _check_keys(b, {'size', 'position'}, f'{where}.table')
        for key in ('size', 'position'):
            if key not in b:
                raise RobotFileError(f'{where}.table: missing required key '
                                     f'{key!r}')
        size = np.array(to_vector(b['size'], 3, f'{where}.table.size'))
        if not (size > 0).all():
            raise RobotFileError(f'{where}.table.size: every side must be '
                                 f'> 0 m, got {size.tolist()}')
        table = (size, np.array(to_vector(b['position'], 3,
                                          f'{where}.table.position')))
    if block.get('pusher') is not None:
        pusher = _pusher(_mapping(block['pusher'], f'{where}.pusher'),
                         f'{where}.pusher')
    return Contacts(floor, table, pusher)


def _pusher(b, where):
    _check_keys(b, {'link', 'point', 'direction', 'schedule'}, where)
    for key in ('link', 'direction', 'schedule'):
        if key not in b:
            raise RobotFileError(f'{where}: missing required key {key!r}')
    if not isinstance(b['link'], str) or not b['link']:
        raise RobotFileError(f'{where}.link: must be a link name')
    point = np.array(to_vector(b.get('point', [0.0] * 3), 3,
                               f'{where}.point'))
    direction = np.array(to_vector(b['direction'], 3, f'{where}.direction'))
    norm = float(np.linalg.norm(direction))
    if not norm > 0.0:
        raise RobotFileError(f'{where}.direction: must be a nonzero vector')
    rows = b['schedule']
    if not isinstance(rows, list) or not rows or len(rows) > 10000:
        raise RobotFileError(f'{where}.schedule: must be a list of 1 to '
                             f'10000 {{t, force}}')
    times, forces = [], []
    for i, row in enumerate(rows):
        w = f'{where}.schedule[{i}]'
        _mapping(row, w)
        _check_keys(row, {'t', 'force'}, w)
        times.append(to_number(row.get('t'), f'{w}.t'))
        force = to_number(row.get('force'), f'{w}.force')
        if force < 0.0:
            raise RobotFileError(f'{w}.force: must be >= 0 N (a pusher '
                                 f'presses), got {force}')
        forces.append(force)
    if any(b2 < a for a, b2 in zip(times, times[1:])):
        raise RobotFileError(f'{where}.schedule: times must not decrease')
    return Pusher(b['link'], point, direction / norm, np.array(times),
                  np.array(forces))
