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
What inverse_dynamics_node reports: its model, /diagnostics, the service.

Message building only, off the hot path: the log line that says which
model the node runs with (:func:`model_line`, and :func:`mimic_line`
listing a whole robot's mimic joints), the two statuses of its
/diagnostics (:func:`diagnostics`: input counters, model), and the
``~/compute_dynamics`` response (:func:`answer` from the computer's
terms, :func:`failed`).
"""
from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
import numpy as np

from ..core.text import clip


def no_model_text(rejected):
    """Say why there is no model: waiting, or the description rejected."""
    if rejected:
        return (f'no robot model: robot_description rejected: '
                f'{rejected}')
    return 'no robot model yet (waiting for robot_description)'


def model_line(ff, source, mode, payload, params):
    """Return the log line of the model a computer ``ff`` runs."""
    model = ff.model
    effects = (ff.scene.effects.names() if ff.scene is not None
               else 'all rigid-body')
    whole = ''
    if ff.merger is not None:
        count = len(ff.merger.followers)
        whole = (f'whole robot, {model.nb} moving joints'
                 + (f' ({count} of them mimic, listed on the next line)'
                    if count else '')
                 + f', commanding {ff.order.command} on torque_command;'
                 f' joints held {params["joint_states.hold"]} s; ')
    return (
        f'{model.name} ({source}): {model.n} joints '
        f'[{clip(", ".join(ff.output_names), 600)}], {whole}mode '
        f'{mode}, effects '
        f'{effects}, payload {payload[0]} kg, wrench frames '
        f'{clip(str(sorted(ff.wrench.frames)), 400)}'
        + ('' if not params['drives.compensate'] else
           ', drive terms compensated (largest Coulomb friction '
           f'{ff.drives.coulomb.max():.3g}, rotor inertia '
           f'{ff.drives.armature.max():.3g}; newton-euler check lists '
           'them)' if ff.drives is not None else
           ', drives.compensate is on but the robot has no drive '
           'terms')
        + (', without g(q): the robot adds it '
           '(robot_compensates_gravity)'
           if ff.robot_compensates_gravity else ''))


def mimic_line(ff):
    """
    Return the line listing every mimic joint under its leader, or None.

    The start-up line gives their count; this line gives them all,
    never cut (a hand or two grippers have tens of them).
    """
    if ff.merger is None or not ff.merger.followers:
        return None
    leads = {}
    for follower, (lead, _, _) in ff.merger.followers.items():
        leads.setdefault(lead, []).append(follower)
    return (f'{ff.model.name}: {len(ff.merger.followers)} mimic joints, '
            f'each following its leader: ' + '; '.join(
                f'{lead} leads {", ".join(followers)}'
                for lead, followers in leads.items()))


def answer(response, ff, request, now):
    """
    Fill a ComputeDynamics response with D, C, g, tau in output order.

    Raises what ``FeedforwardComputer.terms`` raises (the response then
    is the caller's to fill with :func:`failed`).
    """
    D, C, g, tau = ff.terms(request.name, request.position,
                            request.velocity, request.acceleration, now)
    response.success = True
    response.message = ''
    response.name = list(ff.output_names)
    response.mass_matrix = D.ravel().tolist()
    response.coriolis_matrix = C.ravel().tolist()
    response.gravity = g.tolist()
    response.torque = tau.tolist()
    return response


def failed(response, message):
    """Return a ComputeDynamics response that failed, saying why."""
    response.success = False
    response.message = message
    return response


def diagnostics(name, ff, counts, mode, params, payload, source, rejected):
    """
    Return the node's statuses: input counters, and its model.

    ``name`` is the node's fully qualified name, ``ff`` its computer or
    None, ``rejected`` why the last robot_description was rejected ('' if
    it loaded).
    """
    if ff is None:
        level, message = (
            DiagnosticStatus.ERROR if rejected else DiagnosticStatus.WARN,
            f'{no_model_text(rejected)}: publishing nothing')
    elif rejected:
        level, message = DiagnosticStatus.WARN, (
            f'input counters; the last robot_description was rejected '
            f'({rejected}); the previous model keeps working')
    else:
        level, message = DiagnosticStatus.OK, 'input counters'
    status = DiagnosticStatus(
        level=level, name=name, message=message,
        hardware_id=ff.model.name if ff is not None else '')
    status.values = [KeyValue(key=k, value=str(v))
                     for k, v in counts.items()]
    model = DiagnosticStatus(
        level=DiagnosticStatus.OK, name=name + ': model',
        message=f'mode {mode}',
        hardware_id=ff.model.name if ff is not None else '')
    model.values = [
        KeyValue(key='mode', value=mode),
        KeyValue(key='robot_compensates_gravity', value=str(
            params['robot_compensates_gravity']).lower()),
        KeyValue(key='payload.mass', value=repr(payload[0])),
        KeyValue(key='payload.com', value=repr(list(payload[1]))),
        KeyValue(key='payload.inertia', value=repr(list(payload[2]))),
        KeyValue(key='source', value=clip(source, 400)),
        KeyValue(key='limits.action', value=params['limits.action']),
        KeyValue(key='torque_bounds', value=repr(
            ff.guard.bounds.tolist() if ff is not None else [])),
        KeyValue(key='torque_bound_sources', value=repr(
            ff.bound_sources if ff is not None else []))]
    return [status, model]


class UpdateTimes:
    """
    The time each joint state took, from its callback to the publish.

    The last ``size`` updates are kept in a ring (no allocation per
    update); :meth:`status` gives their median, 99th percentile and
    largest in microseconds for ``/diagnostics`` (the observer's step is
    included when it runs).
    """

    def __init__(self, size=1000):
        self.times = np.zeros(size)
        self.count = 0

    def add(self, seconds):
        """Record one update's duration."""
        self.times[self.count % len(self.times)] = seconds
        self.count += 1

    def status(self, name):
        """Return the DiagnosticStatus of the last updates' times."""
        status = DiagnosticStatus(level=DiagnosticStatus.OK,
                                  name=name + ': update time')
        kept = self.times[:min(self.count, len(self.times))] * 1e6
        if not len(kept):
            status.message = 'no joint state answered yet'
            status.values = [KeyValue(key='updates', value='0')]
            return status
        median, p99 = np.percentile(kept, [50, 99])
        status.message = (f'joint state to torques, the last {len(kept)} '
                          f'updates: median {median:.0f} us, 99th '
                          f'percentile {p99:.0f} us')
        status.values = [
            KeyValue(key='updates', value=str(self.count)),
            KeyValue(key='window', value=str(len(kept))),
            KeyValue(key='median_us', value=f'{median:.1f}'),
            KeyValue(key='p99_us', value=f'{p99:.1f}'),
            KeyValue(key='max_us', value=f'{kept.max():.1f}')]
        return status
