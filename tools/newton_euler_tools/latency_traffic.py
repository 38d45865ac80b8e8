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
What the latency bench sends: the Puma's joint states at 1 kHz.

A seeded random walk of positions and velocities within the joint limits
that turns back with a spring before them (``Walk``, ``random_walk``),
with efforts (the model's own torques for the motion); the reused
message and its stamp; the stamp read back from a raw (CDR) answer.
"""
import array
import struct
import time

import numpy as np

NODE_NAME = 'inverse_dynamics_node'
NODE_TOPIC = '/inverse_dynamics_node/torques'
WRENCH_TOPIC = '/inverse_dynamics_node/external_wrench'
CONTACT_TOPIC = '/inverse_dynamics_node/contact'
ECHO_TOPIC = '/echo_node/torques'
LOOP_TOPIC = '/latency_bench/loop'
INPUT_TOPIC = '/joint_states'


JOINTS = ('joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'joint6')


# used when the robot file cannot be read: the puma560's limits (rad)
FALLBACK_LIMITS = ((-2.7925, 2.7925), (-0.7854, 3.9270), (-3.9270, 0.7854),
                   (-1.9199, 2.9671), (-1.7453, 1.7453), (-4.6426, 4.6426))


WALL_STIFFNESS = 400.0          # 1/s^2: the walk's turn-back spring


_CDR_LE = b'\x00\x01'


_STAMP = struct.Struct('<iI')   # header.stamp.sec, .nanosec after the


_STAMP_BE = struct.Struct('>iI')  # 4-byte CDR encapsulation header


def raw_stamp_ns(raw):
    """Return header.stamp of a serialized JointState, in ns."""
    st = _STAMP if raw[:2] == _CDR_LE else _STAMP_BE
    sec, nsec = st.unpack_from(raw, 4)
    return sec * 1_000_000_000 + nsec


def puma_model():
    """Return the bundled puma560 model (None if it cannot be read)."""
    try:
        import warnings
        from newton_euler_ros.core import load_robot
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            model = load_robot('puma560')
        return model if model.n == len(JOINTS) else None
    except Exception:
        return None


def joint_limits(model=None):
    if model is not None:
        return tuple((lim['lower'], lim['upper']) for lim in model.limits)
    return FALLBACK_LIMITS


class Walk:
    """The joint states of a phase: positions, velocities, efforts."""

    def __init__(self, positions, velocities, efforts):
        self.positions = positions
        self.velocities = velocities
        self.efforts = efforts

    def __len__(self):
        return len(self.positions)


def random_walk(n, rate, seed, limits, model=None):
    """
    Return a :class:`Walk` of n states 1/rate s apart, as array('d').

    The accelerations are a random walk (smooth, bounded motion),
    velocities are capped at 2 rad/s, and a joint beyond 90% of its
    range is turned back by a stiff spring (velocities stay continuous;
    it stays within its limits).  The efforts are ``model``'s own
    torques for the motion, tau(q, qd, qdd) with qdd the acceleration
    the walk integrated: what the drives of that arm would report, so a
    momentum observer on the same model sees no external torque (empty
    without a model).
    """
    rng = np.random.default_rng(seed)
    lo = np.array([a for a, _ in limits])
    hi = np.array([b for _, b in limits])
    mid, half = (lo + hi) / 2, 0.9 * (hi - lo) / 2
    lo, hi = mid - half, mid + half
    dt = 1.0 / rate
    q = mid + rng.uniform(-0.5, 0.5, 6) * half
    qd = rng.uniform(-0.5, 0.5, 6)
    qdd = np.zeros(6)
    pos = np.empty((n, 6))
    vel = np.empty((n, 6))
    acc = np.empty((n, 6))
    for k in range(n):
        qdd = 0.995 * qdd + rng.normal(0.0, 0.5, 6)
        # the wall: zero at 90% of the range, so no jump in acceleration
        wall = WALL_STIFFNESS * (np.minimum(hi - q, 0.0)
                                 + np.maximum(lo - q, 0.0))
        new_qd = np.clip(qd + (qdd + wall) * dt, -2.0, 2.0)
        acc[k] = (new_qd - qd) / dt
        qd = new_qd
        q = q + qd * dt
        pos[k], vel[k] = q, qd
    if model is not None:
        from newton_euler_ros.core import inverse_dynamics_batch
        eff = inverse_dynamics_batch(model, pos, vel, acc)
        efforts = [array.array('d', e) for e in eff]
    else:
        efforts = [array.array('d')] * n
    return Walk([array.array('d', p) for p in pos],
                [array.array('d', v) for v in vel], efforts)


def _new_msg():
    from sensor_msgs.msg import JointState
    msg = JointState()
    msg.name = list(JOINTS)
    return msg


class _StampClock:
    """Strictly increasing time.time_ns() stamps (the matching key)."""

    def __init__(self):
        self.last = 0

    def __call__(self):
        t = time.time_ns()
        if t <= self.last:
            t = self.last + 1
        self.last = t
        return t


def _set_stamp(msg, t):
    msg.header.stamp.sec = t // 1_000_000_000
    msg.header.stamp.nanosec = t % 1_000_000_000
