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
``newton-euler export``: the written YAML rebuilds the identified robot.

The check is the physics, not the text: each written file is turned back
into link inertials the way its description's xacro does it
(ur_description's ``ur_macro.xacro``: ``<origin xyz=<part>_cog
rpy=rotation.<part>>`` around ``tensor.<part>``; franka_description's
``franka-inertials``: ``origin xyz/rpy``, ``mass``, ``inertia xx..zz``),
and the robot so built must have the identified URDF's mass matrix and
gravity torques.  The UR is built, as ur_description builds it, from
UR5's published kinematics (modified-DH frames, every axis z) and
physical parameters; the Franka is example-robot-data's Panda.
"""
import warnings
import xml.etree.ElementTree as ET

from newton_euler_ros.cli import main
from newton_euler_ros.core import gravity_torques, load_urdf, mass_matrix
import numpy as np
import pytest
import yaml

PI = np.pi
UR_PARTS = ('shoulder', 'upper_arm', 'forearm', 'wrist_1', 'wrist_2',
            'wrist_3')
UR_JOINTS = ('shoulder_pan_joint', 'shoulder_lift_joint', 'elbow_joint',
             'wrist_1_joint', 'wrist_2_joint', 'wrist_3_joint')
# ur_description config/ur5/default_kinematics.yaml: x y z roll pitch yaw
UR5_KINEMATICS = {
    'shoulder': (0, 0, 0.089159, 0, 0, 0),
    'upper_arm': (0, 0, 0, PI / 2, 0, 0),
    'forearm': (-0.425, 0, 0, 0, 0, 0),
    'wrist_1': (-0.39225, 0, 0.10915, 0, 0, 0),
    'wrist_2': (0, -0.09465, 0, PI / 2, 0, 0),
    'wrist_3': (0, 0.0823, 0, PI / 2, PI, PI),
}
# ur_description config/ur5/physical_parameters.yaml's layout and values
UR5_TEMPLATE = """\
# Physical parameters

offsets:
  shoulder_offset: 0.13585 # measured from model
  elbow_offset: 0.0165 # measured from model

inertia_parameters:
  base_mass: 4.0  # This mass might be incorrect
  shoulder_mass: 3.7000
  upper_arm_mass: 8.3930
  forearm_mass: 2.33
  wrist_1_mass: 1.2190
  wrist_2_mass: 1.2190
  wrist_3_mass: 0.1879

  shoulder_radius: 0.060   # manually measured
  upper_arm_radius: 0.054  # manually measured
  elbow_radius: 0.060      # manually measured
  forearm_radius: 0.040    # manually measured
  wrist_radius: 0.045      # manually measured

  links:
    base:
      radius: 0.06
      length: 0.05

  center_of_mass:
    shoulder_cog: {x: 0.0, y: -0.00193, z: -0.02561}
    upper_arm_cog: {x: -0.2125, y: 0.0, z: 0.11336}
    forearm_cog: {x: -0.24225, y: 0.0, z: 0.0265}
    wrist_1_cog: {x: 0.0, y: -0.01634, z: -0.0018}
    wrist_2_cog: {x: 0.0, y: 0.01634, z: -0.0018}
    wrist_3_cog: {x: 0.0, y: 0.0, z: -0.001159}

  rotation:
    shoulder: {roll: 0, pitch: 0, yaw: 0}
    upper_arm: {roll: 0, pitch: 1.570796326794897, yaw: 0}
    forearm: {roll: 0, pitch: 1.570796326794897, yaw: 0}
    wrist_1: {roll: 0, pitch: 0, yaw: 0}
    wrist_2: {roll: 0, pitch: 0, yaw: 0}
    wrist_3: {roll: 0, pitch: 0, yaw: 0}

  tensor:
    shoulder: {ixx: 0.014972358333333331, ixy: 0, ixz: 0,
               iyy: 0.014972358333333331, iyz: 0, izz: 0.01040625}
    upper_arm: {ixx: 0.13388583541666665, ixy: 0, ixz: 0,
                iyy: 0.13388583541666665, iyz: 0, izz: 0.0151074}
    forearm: {ixx: 0.031216803515624995, ixy: 0, ixz: 0,
              iyy: 0.031216803515624995, iyz: 0, izz: 0.004095}
    wrist_1: {ixx: 0.002013889583333333, ixy: 0, ixz: 0,
              iyy: 0.002013889583333333, iyz: 0, izz: 0.0021942}
    wrist_2: {ixx: 0.0018310395833333333, ixy: 0, ixz: 0,
              iyy: 0.0018310395833333333, iyz: 0, izz: 0.0021942}
    wrist_3: {ixx: 8.062475833333332e-05, ixy: 0, ixz: 0,
              iyy: 8.062475833333332e-05, iyz: 0, izz: 0.0001321171875}
"""
TENSOR_KEYS = ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')
FRANKA_KEYS = ('xx', 'xy', 'xz', 'yy', 'yz', 'zz')


def _f(values):
    return ' '.join(repr(float(v)) for v in values)


def ur_urdf(physical, prefix=''):
    """Return the URDF ur_macro.xacro makes of ``physical``, UR5's kinematics."""
    ip = physical['inertia_parameters']
    base = ip['links']['base']
    m, r, h = ip['base_mass'], base['radius'], base['length']
    side = m * (3 * r * r + h * h) / 12
    out = ['<robot name="ur5">', f'<link name="{prefix}base_link"/>',
           f'<link name="{prefix}base_link_inertia"><inertial>'
           f'<mass value="{m}"/><origin xyz="0 0 0" rpy="0 0 0"/>'
           f'<inertia ixx="{side}" ixy="0" ixz="0" iyy="{side}" iyz="0" '
           f'izz="{m * r * r / 2}"/></inertial></link>',
           f'<joint name="{prefix}base_link-base_link_inertia" type="fixed">'
           f'<parent link="{prefix}base_link"/>'
           f'<child link="{prefix}base_link_inertia"/>'
           f'<origin xyz="0 0 0" rpy="0 0 {PI!r}"/></joint>']
    parent = 'base_link_inertia'
    for part, joint in zip(UR_PARTS, UR_JOINTS):
        cog = ip['center_of_mass'][f'{part}_cog']
        rot = ip['rotation'][part]
        t = ip['tensor'][part]
        x, y, z, roll, pitch, yaw = UR5_KINEMATICS[part]
        out.append(
            f'<link name="{prefix}{part}_link"><inertial>'
            f'<mass value="{ip[part + "_mass"]!r}"/>'
            f'<origin rpy="{rot["roll"]} {rot["pitch"]} {rot["yaw"]}" '
            f'xyz="{cog["x"]!r} {cog["y"]!r} {cog["z"]!r}"/>'
            '<inertia ' + ' '.join(f'{k}="{float(t[k])!r}"'
                                   for k in TENSOR_KEYS) + '/>'
            '</inertial></link>'
            f'<joint name="{prefix}{joint}" type="revolute">'
            f'<parent link="{prefix}{parent}"/>'
            f'<child link="{prefix}{part}_link"/>'
            f'<origin xyz="{_f((x, y, z))}" rpy="{_f((roll, pitch, yaw))}"/>'
            '<axis xyz="0 0 1"/>'
            '<limit lower="-6.28" upper="6.28" effort="150" velocity="3"/>'
            '<dynamics damping="0" friction="0"/></joint>')
        parent = f'{part}_link'
    out.append('</robot>')
    return '\n'.join(out)


def random_inertial(rng, mass):
    """Return a physical mass, com, rpy, tensor about the com in rpy's axes."""
    m = mass * rng.uniform(0.7, 1.4)
    com = rng.uniform(-0.15, 0.15, 3)
    rpy = rng.uniform(-PI, PI, 3)
    moments = rng.uniform(0.2, 1.0, 3) * 0.05 * m
    moments[2] = rng.uniform(abs(moments[0] - moments[1]),
                             moments[0] + moments[1])   # triangle
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    return m, com, rpy, Q @ np.diag(moments) @ Q.T


def set_inertial(link_el, m, com, rpy, inertia, keys=TENSOR_KEYS):
    old = link_el.find('inertial')
    if old is not None:
        link_el.remove(old)
    el = ET.SubElement(link_el, 'inertial')
    ET.SubElement(el, 'origin', xyz=_f(com), rpy=_f(rpy))
    ET.SubElement(el, 'mass', value=repr(float(m)))
    idx = {'xx': (0, 0), 'xy': (0, 1), 'xz': (0, 2), 'yy': (1, 1),
           'yz': (1, 2), 'zz': (2, 2)}
    ET.SubElement(el, 'inertia', **{
        'i' + k: repr(float(inertia[idx[k]])) for k in FRANKA_KEYS})


def perturbed(text, links, seed):
    """``text`` with random physical inertials on ``links``."""
    rng = np.random.default_rng(seed)
    root = ET.fromstring(text)
    for el in root.findall('link'):
        if el.get('name') in links:
            mass = float(el.find('inertial/mass').get('value'))
            set_inertial(el, *random_inertial(rng, mass))
    return ET.tostring(root, encoding='unicode')


def load(text, **chain):
    with warnings.catch_warnings():
        warnings.simplefilter('ignore')
        return load_urdf(text, **chain)


def dynamics_gap(a, b, seed=0, count=6):
    """Largest |M_a - M_b| and |g_a - g_b| over random configurations."""
    rng = np.random.default_rng(seed)
    gap = 0.0
    for _ in range(count):
        q = rng.uniform(-PI, PI, a.n)
        gap = max(gap, np.max(np.abs(mass_matrix(a, q) - mass_matrix(b, q))),
                  np.max(np.abs(gravity_torques(a, q)
                                - gravity_torques(b, q))))
    return gap


def run(args, capsys):
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def one_error_line(code, err):
    lines = [x for x in err.splitlines() if not x.startswith('note:')]
    assert code == 2, err
    assert len(lines) == 1 and lines[0].startswith('newton-euler: error: '), \
        err
    return lines[0]


@pytest.fixture
def ur5(tmp_path):
    template = tmp_path / 'physical_parameters.yaml'
    template.write_text(UR5_TEMPLATE)
    nominal = tmp_path / 'ur5.urdf'
    nominal.write_text(ur_urdf(yaml.safe_load(UR5_TEMPLATE)))
    return template, nominal


def test_ur_nominal_gives_back_the_template(ur5, tmp_path, capsys):
    """Export the nominal UR5: its own inertials, rotated ones included."""
    template, nominal = ur5
    out = tmp_path / 'out.yaml'
    code, _, err = run(['export', nominal, '--format', 'ur', '-o', out,
                        '--template', template], capsys)
    assert code == 0, err
    got = yaml.safe_load(out.read_text())
    want = yaml.safe_load(UR5_TEMPLATE)
    ip, wip = got['inertia_parameters'], want['inertia_parameters']
    for part in UR_PARTS:
        assert ip[f'{part}_mass'] == pytest.approx(wip[f'{part}_mass'],
                                                   abs=1e-12)
        for k in 'xyz':
            assert ip['center_of_mass'][f'{part}_cog'][k] == pytest.approx(
                wip['center_of_mass'][f'{part}_cog'][k], abs=1e-12)
        for k in TENSOR_KEYS:
            assert ip['tensor'][part][k] == pytest.approx(
                wip['tensor'][part][k], abs=1e-12), (part, k)
    # what identification does not give is the template's
    assert got['offsets'] == want['offsets']
    for key in ('base_mass', 'links', 'rotation', 'shoulder_radius',
                'wrist_radius'):
        assert ip[key] == wip[key]


def test_ur_identified_is_rebuilt_by_the_xacro_rule(ur5, tmp_path, capsys):
    template, nominal = ur5
    links = [f'{p}_link' for p in UR_PARTS]
    identified = tmp_path / 'identified.urdf'
    identified.write_text(perturbed(nominal.read_text(), links, seed=7))
    # a rotation of no symmetry as well as the published quarter turns
    template.write_text(UR5_TEMPLATE.replace(
        'wrist_1: {roll: 0, pitch: 0, yaw: 0}',
        'wrist_1: {roll: 0.3, pitch: 0.2, yaw: -0.5}'))
    out = tmp_path / 'identified_physical_parameters.yaml'
    code, stdout, err = run(['export', identified, '--format', 'ur', '-o',
                             out, '--template', template], capsys)
    assert code == 0, err
    assert str(out) in stdout
    written = yaml.safe_load(out.read_text())
    truth = load(identified.read_text())
    rebuilt = load(ur_urdf(written))
    gap = dynamics_gap(truth, rebuilt)
    with capsys.disabled():
        print(f'UR5 identified vs rebuilt from physical_parameters.yaml: '
              f'max |dM|, |dg| = {gap:.2e}')
    assert gap < 1e-9
    # the test can fail: the nominal robot, and the tensors read without
    # the template's rotation, are other robots
    assert dynamics_gap(truth, load(nominal.read_text())) > 1e-2
    for part in ('upper_arm', 'forearm'):
        written['inertia_parameters']['rotation'][part]['pitch'] = 0.0
    assert dynamics_gap(truth, load(ur_urdf(written))) > 1e-4


def test_ur_without_template_writes_inertia_parameters(ur5, tmp_path,
                                                       capsys):
    template, nominal = ur5
    identified = tmp_path / 'identified.urdf'
    identified.write_text(perturbed(
        ur_urdf(yaml.safe_load(UR5_TEMPLATE), prefix='left_'),
        [f'left_{p}_link' for p in UR_PARTS], seed=3))
    out = tmp_path / 'inertia.yaml'
    code, _, err = run(['export', identified, '--format', 'ur', '-o', out],
                       capsys)
    assert code == 0, err
    assert len(err.splitlines()) == 1 and 'without --template' in err
    written = yaml.safe_load(out.read_text())
    assert list(written) == ['inertia_parameters']
    merged = yaml.safe_load(UR5_TEMPLATE)
    merged['inertia_parameters'].update(written['inertia_parameters'])
    assert all(r == {'roll': 0.0, 'pitch': 0.0, 'yaw': 0.0}
               for r in merged['inertia_parameters']['rotation'].values())
    gap = dynamics_gap(load(identified.read_text()),
                       load(ur_urdf(merged, prefix='left_')))
    assert gap < 1e-9


def franka_rebuilt(text, written, prefix):
    """``text`` with franka_description's inertials of ``written``."""
    root = ET.fromstring(text)
    for el in root.findall('link'):
        name = el.get('name')
        if not name.startswith(prefix) or name[len(prefix):] not in written:
            continue
        entry = written[name[len(prefix):]]
        xyz = [float(v) for v in entry['origin']['xyz'].split()]
        rpy = [float(v) for v in entry['origin']['rpy'].split()]
        t = entry['inertia']
        inertia = np.array([[t['xx'], t['xy'], t['xz']],
                            [t['xy'], t['yy'], t['yz']],
                            [t['xz'], t['yz'], t['zz']]])
        set_inertial(el, entry['mass'], xyz, rpy, inertia)
    return ET.tostring(root, encoding='unicode')


@pytest.mark.parametrize('prefix', ['panda_', 'fr3_'])
def test_franka_identified_is_rebuilt(prefix, tmp_path, capsys):
    from newton_euler_tools.peers import example_robot_urdf
    with open(example_robot_urdf('panda_description/urdf/panda.urdf'),
              encoding='utf-8') as fh:
        published = fh.read().replace('panda_', prefix)
    links = [f'{prefix}link{i}' for i in range(1, 8)]
    identified = tmp_path / 'identified.urdf'
    identified.write_text(perturbed(published, links, seed=11))
    out = tmp_path / 'inertials.yaml'
    code, _, err = run(['export', identified, '--format', 'franka', '-o',
                        out], capsys)
    assert code == 0, err
    written = yaml.safe_load(out.read_text())
    assert list(written) == [f'link{i}' for i in range(8)]
    chain = {'base': f'{prefix}link0', 'tip': f'{prefix}link8'}
    truth = load(identified.read_text(), **chain)
    rebuilt = load(franka_rebuilt(published, written, prefix), **chain)
    gap = dynamics_gap(truth, rebuilt)
    with capsys.disabled():
        print(f'Panda ({prefix}) identified vs rebuilt from '
              f'inertials.yaml: max |dM|, |dg| = {gap:.2e}')
    assert gap < 1e-9
    assert dynamics_gap(truth, load(published, **chain)) > 1e-2
    # link0, the fixed base, is the published one
    assert written['link0']['mass'] == 0.629769
    # the explicit prefix writes the same file
    again = tmp_path / 'again.yaml'
    code, _, err = run(['export', identified, '--format', 'franka', '-o',
                        again, '--prefix', prefix], capsys)
    assert code == 0 and again.read_text() == out.read_text(), err


def test_errors_are_one_line(ur5, tmp_path, capsys):
    from newton_euler_tools.peers import example_robot_urdf
    template, nominal = ur5
    panda = example_robot_urdf('panda_description/urdf/panda.urdf')
    ros1_ur5 = example_robot_urdf('ur_description/urdf/ur5_robot.urdf')
    out = tmp_path / 'out.yaml'

    def error(*args):
        line = one_error_line(*run(['export', *args], capsys)[::2])
        assert not out.exists(), line
        return line

    # a link the format needs is missing
    line = error(panda, '--format', 'ur', '-o', out)
    assert "'shoulder_link'" in line and 'physical_parameters' in line
    line = error(panda, '--format', 'franka', '-o', out, '--prefix', 'fr3_')
    assert "'fr3_link1'" in line and 'inertials.yaml' in line
    # other link frames (UR's ROS 1 description turns about y)
    line = error(ros1_ur5, '--format', 'ur', '-o', out)
    assert "'shoulder_lift_joint'" in line and 'ROS 1' in line
    # a mass that is not positive
    bad = tmp_path / 'massless.urdf'
    bad.write_text(nominal.read_text().replace(
        '<mass value="1.219"/>', '<mass value="0.0"/>', 1))
    assert bad.read_text() != nominal.read_text()
    line = error(bad, '--format', 'ur', '-o', out)
    assert "'wrist_1_link'" in line and 'positive' in line
    # bad templates
    for text, named in [
            ('offsets: [1, 2\n', 'not valid YAML'),
            ('- 1\n- 2\n', 'mapping'),
            ('inertia_parameters: {}\n', "'offsets'"),
            (UR5_TEMPLATE.replace('upper_arm: {roll: 0, pitch: '
                                  '1.570796326794897, yaw: 0}', ''),
             'rotation.upper_arm'),
            (UR5_TEMPLATE.replace('forearm: {roll: 0,', 'forearm: {roll: x,'),
             'rotation.forearm.roll')]:
        tpl = tmp_path / 'template.yaml'
        tpl.write_text(text)
        line = error(nominal, '--format', 'ur', '-o', out, '--template', tpl)
        assert named in line and 'template' in line, line
    line = error(nominal, '--format', 'ur', '-o', out, '--template',
                 tmp_path / 'none.yaml')
    assert 'none.yaml' in line
    line = error(panda, '--format', 'franka', '-o', out, '--template',
                 template)
    assert '--template' in line
    line = error(nominal, '--format', 'ur', '-o', tmp_path / 'no' / 'x.yaml')
    assert 'no such directory' in line
    # an existing output is kept unless --overwrite
    out.write_text('mine\n')
    code, _, err = run(['export', nominal, '--format', 'ur', '-o', out],
                       capsys)
    assert 'exists' in one_error_line(code, err) and '--overwrite' in err
    assert out.read_text() == 'mine\n'
    code, _, err = run(['export', nominal, '--format', 'ur', '-o', out,
                        '--overwrite'], capsys)
    assert code == 0, err
    assert 'inertia_parameters' in yaml.safe_load(out.read_text())


def test_the_command_offers_the_formats_the_writer_has():
    from newton_euler_ros import cli_export
    from newton_euler_ros.ident import export
    assert tuple(cli_export.FORMATS) == tuple(export.FORMATS)
