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
``newton-euler excite`` keeps a table-mounted arm off its table.

A UR5 (example-robot-data's published URDF, with its collision meshes)
from its usual home pose: without the floor the excitation drives the
tool far below the base plane; with it, every point of the written
trajectory is checked independently, by Pinocchio's forward kinematics
and its own loading of the collision meshes (coal).  The user's joint
ranges and speed and acceleration limits hold at every point.
"""
import json
import os
import subprocess
import sys

from newton_euler_tools.peers import example_robot_urdf
import numpy as np
import pytest

UR5 = example_robot_urdf('ur_description/urdf/ur5_robot.urdf')
HOME = [0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0.0]
MARGIN = 0.05
QUICK = ['--period', '8', '--harmonics', '4', '--budget', '120',
         '--evaluations', '120']   # the same motion however loaded


def excite(tmp_path, *args, name='x.json'):
    out = tmp_path / name
    proc = subprocess.run(
        [sys.executable, '-m', 'newton_euler_ros.cli', 'excite', UR5,
         '--base', 'base_link', '--tip', 'tool0', '-o', str(out), *QUICK,
         *args], capture_output=True, text=True, timeout=300,
        env=dict(os.environ))
    traj = json.loads(out.read_text()) if out.exists() else None
    return proc, traj


class Pinocchio:
    """Frame origins and collision-mesh vertices, by Pinocchio and coal."""

    def __init__(self):
        import pinocchio as pin
        self.pin = pin
        self.model = pin.buildModelFromUrdf(UR5)
        share = UR5.split('example-robot-data')[0]
        self.geom = pin.buildGeomFromUrdf(self.model, UR5, pin.COLLISION,
                                          package_dirs=[share])
        self.data = self.model.createData()
        self.gdata = self.geom.createData()
        # the base link's own mesh is the mount: it never moves
        self.moving = [o for o in self.geom.geometryObjects
                       if o.parentJoint > 0]
        # six meshes and ee_link's small box
        assert len(self.moving) == 7, 'collision geometry not loaded'

    def lowest(self, q):
        """{frame: z} of the moving frames; {mesh: lowest z}."""
        pin = self.pin
        q = np.asarray(q, dtype=np.float64)
        pin.framesForwardKinematics(self.model, self.data, q)
        pin.updateGeometryPlacements(self.model, self.data, self.geom,
                                     self.gdata)
        frames = {f.name: self.data.oMf[i].translation[2]
                  for i, f in enumerate(self.model.frames)
                  if f.parentJoint > 0}
        meshes = {}
        for obj in self.moving:
            k = self.geom.getGeometryId(obj.name)
            M = self.gdata.oMg[k]
            geo = obj.geometry
            if hasattr(geo, 'halfSide'):
                v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1)
                              for z in (-1, 1)]) * geo.halfSide
            else:
                v = np.asarray(geo.vertices()) * obj.meshScale
            meshes[obj.name] = float((v @ M.rotation.T + M.translation)
                                     [:, 2].min())
        return frames, meshes


@pytest.fixture(scope='module')
def pino():
    return Pinocchio()


def _positions(traj):
    return np.array([p['positions'] for p in traj['points']])


def test_without_the_floor_the_ur5_goes_through_its_table(tmp_path, pino):
    proc, traj = excite(tmp_path, '--start', *map(str, HOME), '--no-floor')
    assert proc.returncode == 0, proc.stderr
    lowest = min(min(pino.lowest(q)[0].values()) for q in _positions(traj))
    # the measured problem: the tool far below the base plane
    assert lowest < -0.2, lowest


def test_the_ur5_from_home_keeps_5_cm_off_its_table(tmp_path, pino):
    proc, traj = excite(tmp_path, '--start', *map(str, HOME))
    assert proc.returncode == 0, proc.stderr
    assert 'clearance kept at every written point' in proc.stdout
    Q = _positions(traj)
    # at rest at the start, at both ends
    for p in (traj['points'][0], traj['points'][-1]):
        np.testing.assert_allclose(p['positions'], HOME, atol=1e-9)
        np.testing.assert_allclose(p['velocities'], 0.0, atol=1e-9)
        np.testing.assert_allclose(p['accelerations'], 0.0, atol=1e-9)
    # the arm moves, and much (every joint swings)
    assert (np.ptp(Q, axis=0) > 0.2).all(), np.ptp(Q, axis=0)
    # every point, by Pinocchio: every moving frame and every moving
    # collision mesh stays 5 cm above the base plane, except the two
    # whose meshes reach down to the mount at home (the shoulder casing
    # and the upper arm's round end about the shoulder-lift axis): they
    # never come nearer than they start
    frames0, meshes0 = pino.lowest(HOME)
    held = {k for k, v in meshes0.items() if v < MARGIN}
    assert held == {'shoulder_link_0', 'upper_arm_link_0'}, meshes0
    low_f, low_m = {}, {}
    for q in Q:
        frames, meshes = pino.lowest(q)
        for k, v in frames.items():
            low_f[k] = min(low_f.get(k, np.inf), v)
        for k, v in meshes.items():
            low_m[k] = min(low_m.get(k, np.inf), v)
    assert min(low_f.values()) >= MARGIN - 1e-6, low_f
    for k, v in low_m.items():
        need = meshes0[k] - 0.002 if k in held else MARGIN
        assert v >= need - 1e-6, (k, v, need)
    # the constraint binds (the motion is not just small): some mesh
    # comes within a centimetre of the margin
    assert min(v for k, v in low_m.items() if k not in held) < MARGIN + 0.01
    assert 'the motion scaled to' in proc.stdout


def test_a_wall_a_lower_floor_and_the_users_limits(tmp_path, pino):
    # a wall at y = 0.35 (keep y <= 0.35), the table 0.1 m lower, and
    # the user's range, speed and acceleration limits
    proc, traj = excite(tmp_path, '--start', *map(str, HOME),
                        '--floor', '-0.1', '--plane', '0', '-1', '0',
                        '-0.35', '--max-velocity', '1.5',
                        '--max-acceleration', '3', '--range',
                        'wrist_3_joint', '-1', '1')
    assert proc.returncode == 0, proc.stderr
    Q = _positions(traj)
    V = np.array([p['velocities'] for p in traj['points']])
    A = np.array([p['accelerations'] for p in traj['points']])
    assert np.abs(V).max() <= 1.5 + 1e-9
    assert np.abs(A).max() <= 3.0 + 1e-9
    assert -1.0 <= Q[:, 5].min() and Q[:, 5].max() <= 1.0
    ys = []
    for q in _positions(traj):
        pino.pin.framesForwardKinematics(pino.model, pino.data, q)
        ys.append(max(pino.data.oMf[i].translation[1]
                      for i, f in enumerate(pino.model.frames)
                      if f.parentJoint > 0))
        assert min(pino.lowest(q)[0].values()) >= -0.1 + MARGIN - 1e-6
    assert max(ys) <= 0.35 - MARGIN + 1e-6


@pytest.mark.parametrize('args, words', [
    # a wall just beyond the tool (keep x <= 0.58): every motion that
    # the limits allow would have to shrink to nothing
    (['--plane', '-1', '0', '0', '-0.58'],
     'nothing useful fits in the constraints'),
    # a floor above the tool: the start is already through it
    (['--floor', '0.45'], 'beyond the floor z = 0.45'),
    (['--range', 'elbow_joint', '0', '9'], 'not inside its URDF limits'),
    (['--range', 'no_joint', '0', '1'], "no joint 'no_joint'"),
    (['--max-velocity', '1', '2'], 'one value or one per joint'),
    (['--plane', '0', '0', '0', '1'], 'nonzero normal'),
])
def test_refusals_are_one_line_and_write_nothing(tmp_path, args, words):
    proc, traj = excite(tmp_path, '--start', *map(str, HOME), *args)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = [x for x in proc.stderr.splitlines()
             if not x.startswith(('note', 'warning'))]
    assert len(lines) == 1 and words in lines[0], proc.stderr
    assert traj is None


def test_start_is_required(tmp_path):
    proc, traj = excite(tmp_path)
    assert proc.returncode == 2 and '--start' in proc.stderr
    assert traj is None
