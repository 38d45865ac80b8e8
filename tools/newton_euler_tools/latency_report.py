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
What the latency bench reports: percentiles, verdicts, tables, JSON.

``summarize`` turns the send and receive records of a phase into its
figures; ``observer_check`` judges the observer phase; the rest prints
the tables and the PASS/MISS lines and writes the JSON.
"""
import json
import os
import platform

import numpy as np

from .latency_traffic import (CONTACT_TOPIC, NODE_NAME, raw_stamp_ns,
                              WRENCH_TOPIC)

TARGET_P99_US = 1000.0


TARGET_OVERHEAD = 0.50          # (node - echo) / echo, on p50 and on p99


# the observer phase fails when fewer answered JointStates than this share
# came with their ~/external_wrench (the observer did not run)
MIN_OBSERVED = 0.5


class BenchError(Exception):
    """The benchmark could not run (node did not start, ...)."""


def log(line=''):
    print(line, flush=True)


def _pct(x, q):
    return float(np.percentile(x, q)) if len(x) else float('nan')


def summarize(send, received, rate):
    """Return the latency statistics of one phase (matched by stamp)."""
    sent = set(send['stamps'])
    seen = set()
    lat = []
    first = last = None
    duplicates = unknown = 0
    for recv_ns, raw in received:
        s = raw_stamp_ns(raw)
        if s not in sent:
            unknown += 1                  # warm-up / pre-roll answers
        elif s in seen:
            duplicates += 1
        else:
            seen.add(s)
            lat.append(recv_ns - s)
            first = recv_ns if first is None else min(first, recv_ns)
            last = recv_ns if last is None else max(last, recv_ns)
    lat_us = np.array(lat, dtype=np.float64) / 1e3
    n_sent = len(send['stamps'])
    pub_us = np.frombuffer(send['publish_ns'], dtype=np.int64) / 1e3
    late_us = np.frombuffer(send['late_ns'], dtype=np.int64) / 1e3
    out = {
        'sent': n_sent, 'received': len(lat), 'dropped': n_sent - len(lat),
        'duplicates': duplicates, 'skipped_slots': send['skipped'],
        'send_rate_hz': ((n_sent - 1) / send['span_s']
                         if send['span_s'] > 0 else float('nan')),
        'target_rate_hz': rate,
        # answers per second, from the first answer's arrival to the last
        'answer_rate_hz': ((len(lat) - 1) / ((last - first) * 1e-9)
                           if len(lat) > 1 and last > first
                           else float('nan')),
        'latency_us': {
            'p50': _pct(lat_us, 50), 'p90': _pct(lat_us, 90),
            'p99': _pct(lat_us, 99), 'p99.9': _pct(lat_us, 99.9),
            'max': float(lat_us.max()) if len(lat_us) else float('nan'),
            'min': float(lat_us.min()) if len(lat_us) else float('nan'),
            'mean': float(lat_us.mean()) if len(lat_us) else float('nan'),
            'over_1ms': int((lat_us >= 1000.0).sum()),
        },
        'publish_call_us': {'p50': _pct(pub_us, 50), 'p99': _pct(pub_us, 99),
                            'max': float(pub_us.max()) if len(pub_us)
                            else float('nan')},
        'send_lateness_us': {'p50': _pct(late_us, 50),
                             'p99': _pct(late_us, 99),
                             'max': float(late_us.max()) if len(late_us)
                             else float('nan')},
    }
    return out, lat_us


def observer_check(send, received, extras):
    """
    Return what the node's observer published in the timed run, or raise.

    Every answered JointState should come with its ``~/external_wrench``
    (stamped with the JointState's stamp); fewer than ``MIN_OBSERVED`` of
    them means the observer did not run and the phase measured the node
    without it: BenchError.  Also the wrench's latency (receive time -
    stamp), its largest force and moment, and whether ``~/contact`` was
    ever true (the efforts are the model's own torques: it should not).
    """
    from geometry_msgs.msg import WrenchStamped
    from rclpy.serialization import deserialize_message
    sent = set(send['stamps'])
    answered = {raw_stamp_ns(raw) for _, raw in received} & sent
    lat, seen, f_max, m_max, finite = [], set(), 0.0, 0.0, True
    for recv_ns, raw in extras.get(WRENCH_TOPIC, []):
        s = raw_stamp_ns(raw)
        if s not in sent or s in seen:
            continue
        seen.add(s)
        lat.append((recv_ns - s) / 1e3)
        w = deserialize_message(raw, WrenchStamped).wrench
        f = (w.force.x, w.force.y, w.force.z)
        m = (w.torque.x, w.torque.y, w.torque.z)
        finite &= bool(np.isfinite(f + m).all())
        f_max = max(f_max, float(np.linalg.norm(f)))
        m_max = max(m_max, float(np.linalg.norm(m)))
    contacts = extras.get(CONTACT_TOPIC, [])
    out = {'answered': len(answered), 'wrenches': len(seen),
           'wrench_latency_us': {'p50': _pct(lat, 50), 'p99': _pct(lat, 99)},
           'max_force_n': f_max, 'max_moment_nm': m_max,
           'wrench_finite': finite,
           'contact_messages': len(contacts),
           'contact_true': sum(1 for _, raw in contacts
                               if len(raw) > 4 and raw[4] != 0)}
    log(f'observer: {out["wrenches"]} ~/external_wrench for '
        f'{out["answered"]} answered JointStates (latency p50 '
        f'{out["wrench_latency_us"]["p50"]:.0f} / p99 '
        f'{out["wrench_latency_us"]["p99"]:.0f} us); largest |f| '
        f'{f_max:.2f} N, |m| {m_max:.2f} N m; ~/contact true in '
        f'{out["contact_true"]} of {out["contact_messages"]} messages')
    if not answered or len(seen) < MIN_OBSERVED * len(answered):
        raise BenchError(
            f'observer phase: {len(seen)} ~/external_wrench for '
            f'{len(answered)} answered JointStates: the observer did not '
            f'run (see the node log), so this phase measured nothing')
    if not finite:
        raise BenchError('observer phase: a non-finite ~/external_wrench')
    return out


def _loadavg():
    try:
        return list(os.getloadavg())
    except (AttributeError, OSError):
        return None


def _fmt_load(la):
    return ' '.join(f'{x:.2f}' for x in la) if la else 'n/a'


def verdicts(node, echo):
    nl, el = node['latency_us'], echo['latency_us']
    over50 = (nl['p50'] - el['p50']) / el['p50']
    over99 = (nl['p99'] - el['p99']) / el['p99']
    return {
        'ratio_p50': nl['p50'] / el['p50'],
        'ratio_p99': nl['p99'] / el['p99'],
        'overhead_p50': over50, 'overhead_p99': over99,
        'targets': {
            'p99 < 1 ms': {'value': nl['p99'], 'unit': 'us',
                           'pass': bool(nl['p99'] < TARGET_P99_US)},
            'nothing dropped': {'value': node['dropped'], 'unit': 'messages',
                                'pass': node['dropped'] == 0},
            'overhead over echo floor < 50% (p50)': {
                'value': 100 * over50, 'unit': '%',
                'pass': bool(over50 < TARGET_OVERHEAD)},
            'overhead over echo floor < 50% (p99)': {
                'value': 100 * over99, 'unit': '%',
                'pass': bool(over99 < TARGET_OVERHEAD)},
        },
    }


def print_table(phases):
    head = (f'{"":36s}{"p50":>7s}{"p99":>8s}{"p99.9":>8s}{"max":>8s}'
            f'{"sent":>8s}{"recv":>8s}{"drop":>6s}{"sent Hz":>9s}'
            f'{"ans Hz":>8s}{"cpu%":>6s}')
    log('latency = receive time - header.stamp, in us')
    log(head)
    log('-' * len(head))
    for r in phases:
        L = r['latency_us']
        cpu = r.get('node_cpu_percent')
        log(f'{r["label"]:36s}{L["p50"]:7.0f}{L["p99"]:8.0f}'
            f'{L["p99.9"]:8.0f}{L["max"]:8.0f}{r["sent"]:8d}'
            f'{r["received"]:8d}{r["dropped"]:6d}{r["send_rate_hz"]:9.1f}'
            f'{r["answer_rate_hz"]:8.1f}'
            + (f'{cpu:6.0f}' if cpu is not None else f'{"-":>6s}'))
    log('(sent Hz / ans Hz = joint states sent / answers received per '
        'second; cpu% = the node process, % of one core, during the timed '
        'run)')
    for r in phases:
        P, S = r['publish_call_us'], r['send_lateness_us']
        log(f'  {r["label"]}: publish() call p50 {P["p50"]:.1f} / p99 '
            f'{P["p99"]:.1f} us; send lateness p50 {S["p50"]:.1f} / p99 '
            f'{S["p99"]:.1f} / max {S["max"]:.0f} us; skipped slots '
            f'{r["skipped_slots"]}; bench cpu {r["bench_cpu_percent"]:.0f}%'
            + (f'; duplicates {r["duplicates"]}' if r['duplicates'] else '')
            + (f'; torque_command received {r["torque_command_received"]}'
               if 'torque_command_received' in r else ''))


def print_header(args, rclpy_version, slack, load_start):
    """Log the set-up: rate, versions, machine load, the bench's timing."""
    log(f'newton_euler_ros latency benchmark: {args.rate:.0f} Hz x '
        f'{args.duration:g} s per phase; python '
        f'{platform.python_version()}, rclpy {rclpy_version}, '
        f'{os.environ.get("RMW_IMPLEMENTATION", "rmw default (FastDDS)")}')
    log(f'machine: {os.cpu_count()} cpus; load average at start '
        f'{_fmt_load(load_start)}'
        + ('  (WARNING: other work is running; figures will be noisy)'
           if load_start and load_start[0] > 0.5 * (os.cpu_count() or 1)
           else ''))
    log(f'bench: sender = main thread, absolute perf_counter deadlines, '
        f'sleep then spin the last {args.spin_us:g} us, timer slack '
        f'{"1 ns" if slack else "default"}; receiver = its own thread '
        f'spinning the {args.bench_executor} executor; switch interval '
        f'{args.switch_us:g} us during timing')


def observer_verdicts(off, on):
    """Targets of the observer phase (and its figures beside ``off``)."""
    L = on['latency_us']
    out = {'targets': {
        'observer on: p99 < 1 ms': {'value': L['p99'], 'unit': 'us',
                                    'pass': bool(L['p99'] < TARGET_P99_US)},
        'observer on: nothing dropped': {'value': on['dropped'],
                                         'unit': 'messages',
                                         'pass': on['dropped'] == 0}}}
    if off is not None:
        out['added_p50_us'] = L['p50'] - off['latency_us']['p50']
        out['added_p99_us'] = L['p99'] - off['latency_us']['p99']
    return out


def _side_by_side(off, on):
    """Log the observer off / on figures on one line each."""
    def pair(key):
        return (f'{off["latency_us"][key]:.0f} / '
                f'{on["latency_us"][key]:.0f}')
    cpu = [r.get('node_cpu_percent') for r in (off, on)]
    log(f'\nobserver off / on ({NODE_NAME}, SingleThreadedExecutor): p50 '
        f'{pair("p50")} us, p99 {pair("p99")} us, max {pair("max")} us; '
        f'answered {off["answer_rate_hz"]:.1f} / {on["answer_rate_hz"]:.1f}'
        f' Hz of {on["target_rate_hz"]:.0f}; dropped {off["dropped"]} / '
        f'{on["dropped"]}'
        + (f'; node cpu {cpu[0]:.0f}% / {cpu[1]:.0f}%'
           if None not in cpu else ''))


def report(phases, by_key):
    """Log the table, the node/echo verdicts; return (summary, missed)."""
    print_table(phases)
    summary = None
    missed = False
    targets = {}
    if 'node' in by_key and 'echo' in by_key:
        summary = verdicts(by_key['node'], by_key['echo'])
        targets.update(summary['targets'])
        log(f'\nnode / echo: p50 {summary["ratio_p50"]:.2f}x, p99 '
            f'{summary["ratio_p99"]:.2f}x;  overhead over the echo floor: '
            f'p50 {100 * summary["overhead_p50"]:+.0f}%, p99 '
            f'{100 * summary["overhead_p99"]:+.0f}%')
        if 'loop' in by_key:
            lp, ep = by_key['loop']['latency_us'], by_key['echo']['latency_us']
            log(f'bench itself (self-loop, no transport): p50 '
                f'{lp["p50"]:.0f} us = {100 * lp["p50"] / ep["p50"]:.0f}% of '
                f'the echo floor p50 ({ep["p50"]:.0f} us), p99 '
                f'{lp["p99"]:.0f} us')
    if 'observer' in by_key:
        on = by_key['observer']
        ov = observer_verdicts(by_key.get('node'), on)
        summary = dict(summary or {}, observer=ov)
        targets.update(ov['targets'])
        if 'node' in by_key:
            _side_by_side(by_key['node'], on)
        o = on['observer']
        log(f'the observer ran: {o["wrenches"]} ~/external_wrench for '
            f'{o["answered"]} answered JointStates; largest |f| '
            f'{o["max_force_n"]:.2f} N, |m| {o["max_moment_nm"]:.2f} N m; '
            f'~/contact true in {o["contact_true"]} of '
            f'{o["contact_messages"]} messages')
    if targets:
        summary['targets'] = targets
        log('\ntargets:')
        for name, t in targets.items():
            value = ('no answers' if t['value'] != t['value'] else
                     f'{t["value"]:.0f} {t["unit"]}' if t['unit'] != '%'
                     else f'{t["value"]:+.0f}%')
            log(f'  {name:40s} {"PASS" if t["pass"] else "MISS"}  ({value})')
            missed |= not t['pass']
    if 'node' in by_key and 'events' in by_key:
        ev, nd = by_key['events'], by_key['node']
        log(f'executor trade-off: the default SingleThreadedExecutor p50 '
            f'{nd["latency_us"]["p50"]:.0f} / p99 '
            f'{nd["latency_us"]["p99"]:.0f} us at '
            f'{nd.get("node_cpu_percent", float("nan")):.0f}% CPU; '
            f'NEWTON_EULER_EXECUTOR=events p50 '
            f'{ev["latency_us"]["p50"]:.0f} / p99 '
            f'{ev["latency_us"]["p99"]:.0f} us at '
            f'{ev.get("node_cpu_percent", float("nan")):.0f}% CPU, but '
            f'memory unbounded under a flood (test_load_node.py)')
    codes = ', '.join(f'{r["label"]} {r["exit_code"]}'
                      for r in phases if 'exit_code' in r)
    if codes:
        log(f'child exit codes after SIGINT: {codes}')
    return summary, missed


def write_json(args, rclpy_version, slack, load_start, load_end, phases,
               summary):
    """Write every figure of the run to ``args.json``."""
    payload = {
        'rate_hz': args.rate, 'duration_s': args.duration,
        'seed': args.seed, 'domain': args.domain,
        'python': platform.python_version(), 'rclpy': rclpy_version,
        'cpus': os.cpu_count(), 'load_average_start': load_start,
        'load_average_end': load_end,
        'bench': {'executor': args.bench_executor,
                  'spin_us': args.spin_us, 'switch_us': args.switch_us,
                  'timer_slack_1ns': slack, 'preroll_s': args.preroll,
                  'drain_s': args.drain},
        'targets': {'p99_us': TARGET_P99_US,
                    'overhead_over_echo': TARGET_OVERHEAD},
        'phases': phases, 'summary': summary,
    }
    os.makedirs(os.path.dirname(os.path.abspath(args.json)),
                exist_ok=True)
    with open(args.json, 'w') as fh:
        json.dump(payload, fh, indent=1)
    log(f'wrote {args.json}')
