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
Robot files: the bundled ones load, bad ones fail with the promised messages.

Error messages name the file, the link and the field; numbers written by
people are coerced.
"""
import math
import warnings

from newton_euler_ros.core import (bundled_robots, load_robot, RobotFileError,
                                   RobotFileWarning)
from newton_euler_ros.core.robot_file import inspect_robot, Note
import numpy as np
import pytest
import yaml

BUNDLED = ['panda', 'planar_2r', 'planar_rp', 'puma560', 'scara', 'stanford']

GOOD = {
    'name': 'two_link',
    'convention': 'standard',
    'gravity': [0.0, 0.0, -9.81],
    'links': [
        {'name': 'shoulder', 'type': 'revolute', 'a': 1.0, 'alpha': 0.0,
         'd': 0.0, 'theta': 0.0, 'mass': 2.0, 'com': [-0.5, 0.0, 0.0],
         'inertia': [0.01, 0.1, 0.1, 0.0, 0.0, 0.0]},
        {'name': 'slide', 'type': 'prismatic', 'a': 0.0, 'alpha': 0.0,
         'd': 0.2, 'theta': 0.0, 'mass': 1.0, 'com': [0.0, 0.0, -0.1],
         'inertia': [0.02, 0.02, 0.001, 0.0, 0.0, 0.0],
         'limits': {'lower': 0.0, 'upper': 0.5, 'velocity': 1.0,
                    'effort': 100.0}},
    ],
}


def write(tmp_path, data, name='robot.yaml'):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def variant(**link1_changes):
    data = yaml.safe_load(yaml.safe_dump(GOOD))
    for key, value in link1_changes.items():
        if value is None:
            del data['links'][1][key]
        else:
            data['links'][1][key] = value
    return data


def test_bundled_list_is_complete():
    assert set(BUNDLED) <= set(bundled_robots())


@pytest.mark.parametrize('name', BUNDLED)
def test_bundled_robot_loads_with_physical_parameters(name):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', RobotFileWarning)
        model = load_robot(name)
    assert model.n == len(set(model.joint_names))
    assert np.all(model.mass >= 0.0)
    for inertia in model.inertia:
        assert np.allclose(inertia, inertia.T)
        assert np.linalg.eigvalsh(inertia).min() >= -1e-15
    assert np.isfinite(model.links_array).all()


def test_published_puma_triangle_inequality_is_a_note_not_a_warning():
    # accepted as published, quietly: inspect_robot (and `check`) list it
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        load_robot('puma560')
    messages = inspect_robot('puma560')[1]
    assert all(isinstance(m, Note) for m in messages)
    assert len(messages) == 2
    assert 'links[0] (joint1): inertia' in messages[0]
    assert 'triangle inequality' in messages[0]
    assert 'links[2] (joint3)' in messages[1]


def test_good_file_round_trips(tmp_path):
    model = load_robot(write(tmp_path, GOOD))
    assert model.joint_names == ('shoulder', 'slide')
    assert model.joint_types == ('revolute', 'prismatic')
    assert model.limits[1] == {'lower': 0.0, 'upper': 0.5, 'velocity': 1.0,
                               'effort': 100.0}
    assert model.inertia[1][2, 2] == 0.001


def test_numbers_written_by_people_are_coerced(tmp_path):
    text = yaml.safe_dump(GOOD).replace('0.001', '1e-3')
    data = yaml.safe_load(text)
    assert data['links'][1]['inertia'][2] == '1e-3'   # PyYAML's reading
    data['links'][0]['alpha'] = '-pi/2'
    data['links'][1]['theta'] = '3*pi/4'
    model = load_robot(write(tmp_path, data))
    assert model.inertia[1][2, 2] == 1e-3
    assert model.alpha[0] == -math.pi / 2
    assert model.theta[1] == 3 * math.pi / 4


def test_full_3x3_inertia_accepted(tmp_path):
    data = variant(inertia=[[0.02, 0.0, 0.0], [0.0, 0.02, 0.0],
                            [0.0, 0.0, 0.001]])
    assert load_robot(write(tmp_path, data)).inertia[1][2, 2] == 0.001


BAD = [
    (variant(mass=-1.0), r'robot\.yaml: links\[1\] \(slide\): mass: must be '
                         r'>= 0, got -1\.0'),
    (variant(mass='heavy'), r'links\[1\] \(slide\): mass: must be a number'),
    (variant(mass='nan'), r'links\[1\] \(slide\): mass: must be finite'),
    (variant(mass=float('inf')), r'mass: must be finite'),
    (variant(com=[0.0, 0.0]), r'links\[1\] \(slide\): com: must have 3 '
                              r'entries, got 2'),
    (variant(com='0 0 0'), r'com: must be a list of 3 numbers'),
    (variant(inertia=[1.0, 1.0, 1.0, 0.0, 0.0]),
     r'inertia: must have 6 entries, got 5'),
    (variant(inertia=[1.0, 1.0, 1.0, 2.0, 0.0, 0.0]),
     r'links\[1\] \(slide\): inertia: must be positive semidefinite'),
    (variant(inertia=[[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
     r'inertia: must be symmetric'),
    (variant(type='spherical'), r"type: must be 'revolute' or 'prismatic', "
                                r"got 'spherical'"),
    (variant(mass=None), r'links\[1\] \(slide\): missing required key '
                         r"'mass'"),
    (variant(colour='red'), r"links\[1\] \(slide\): unknown key 'colour'"),
    (variant(name='shoulder'), r"name: 'shoulder' is used by an earlier "
                               r'link'),
    (variant(limits={'lower': 1.0, 'upper': 0.0}),
     r'limits: lower \(1\.0\) is above upper \(0\.0\)'),
    (variant(limits={'velocity': 0.0}), r'limits\.velocity: must be > 0'),
    (variant(limits={'min': 0.0}), r"limits: unknown key 'min'"),
    (dict(GOOD, convention='craig'),
     r"convention: must be 'standard' or 'modified', got 'craig'"),
    (dict(GOOD, gravity=[0.0, -9.81]), r'gravity: must have 3 entries'),
    (dict(GOOD, tool={'xyz': [0, 0, 0.1], 'quat': [1, 0, 0, 0]}),
     r"tool: unknown key 'quat'"),
    (dict(GOOD, links=[]), r'links: must be a non-empty list'),
    (dict(GOOD, joints=[]), r"robot\.yaml: unknown key 'joints'"),
    ({k: v for k, v in GOOD.items() if k != 'name'},
     r"missing required key 'name'"),
    ('name: [unclosed\n', r'robot\.yaml: not valid YAML \(line'),
    ('name: a\nname: b\nconvention: standard\nlinks: []\n',
     r"not valid YAML.*key 'name' appears twice"),
    ('- just\n- a list\n', r'robot\.yaml: must be a mapping'),
]


@pytest.mark.parametrize('data, message', BAD)
def test_bad_file_names_file_link_and_field(tmp_path, data, message):
    with pytest.raises(RobotFileError, match=message):
        load_robot(write(tmp_path, data))


def test_missing_file_lists_bundled_robots(tmp_path):
    with pytest.raises(RobotFileError, match=r'no such file.*puma560'):
        load_robot(tmp_path / 'nope.yaml')
    with pytest.raises(RobotFileError, match=r'not a bundled robot'):
        load_robot('no_such_robot')


def test_inspect_returns_warnings_without_raising(tmp_path):
    data = variant(inertia=[1.0, 0.1, 0.1, 0.0, 0.0, 0.0])
    model, found, path = inspect_robot(write(tmp_path, data))
    assert model.n == 2 and path.endswith('robot.yaml')
    assert len(found) == 1 and 'triangle inequality' in found[0]
