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
Every command in the README and in docs/ works when pasted.

Each page's ```bash, ```sh and ```python blocks run in order, as pasted
into bash from the repository root (Python blocks with the venv's
Python), in a scratch copy of the root: the repository's folders are
linked in, while ``build/``, ``out/`` and anything a command writes at
the top are the scratch's own.  A block fails the test on a non-zero
exit status, and the message names the page, the line and the output.

A block that cannot run here says so in the line before its fence:

- ``<!-- doc-test: skip (REASON) -->``: not run (it needs an apt ROS 2,
  hardware, or is the test command itself); it must still be well-formed
  (``bash -n``, or Python that compiles), and REASON must be given.
- ``<!-- doc-test: stop after N s -->``: a command that runs until
  stopped (a node): it must still be running, or have exited 0, after N
  seconds; it then gets SIGINT and must exit 0.
- ``<!-- doc-test: stop at "TEXT" (at most N s) -->``: the same, but
  stopped as soon as it has shown it is up: it must print a line
  containing TEXT (the last line a node logs at start-up) within N
  seconds, without exiting non-zero; a second later it gets SIGINT and
  must exit 0.

Usage synopses with [optional] parts belong in ```text blocks, which are
not run; a bash block must not contain such brackets (checked).
"""
import os
import re
import signal
import subprocess
import sys
import threading
import time

from newton_euler_tools.processes import ros_env
import pytest
from ros_harness import domain_id

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))))
PAGES = ['README.md'] + sorted(
    os.path.join('docs', f) for f in os.listdir(os.path.join(ROOT, 'docs'))
    if f.endswith('.md'))
RUN = {'bash': 'bash', 'sh': 'bash', 'console': None, 'python': 'python'}
DIRECTIVE = re.compile(r'<!--\s*doc-test:\s*(.*?)\s*-->')
# what a scratch root links to (everything a command may read)
LINKED = ('.venv', 'newton_euler_ros', 'newton_euler_interfaces', 'tools',
          'requirements', 'scripts', 'Makefile', 'docs', 'examples',
          'pytest.ini', 'README.md', '.ci')
BLOCK_TIMEOUT = 120.0


def blocks(page):
    """Return (line, language, directive, text) of each fenced block."""
    with open(os.path.join(ROOT, page), encoding='utf-8') as fh:
        lines = fh.read().splitlines()
    found, i = [], 0
    while i < len(lines):
        m = re.match(r'^```\s*([\w+-]*)', lines[i])
        if not m:
            i += 1
            continue
        lang, start = m.group(1).lower(), i
        j = i + 1
        while j < len(lines) and not lines[j].startswith('```'):
            j += 1
        before = next((lines[k] for k in range(start - 1, -1, -1)
                       if lines[k].strip()), '')
        d = DIRECTIVE.search(before)
        found.append((start + 1, lang, d.group(1) if d else None,
                      '\n'.join(lines[start + 1:j]) + '\n'))
        i = j + 1
    return found


def scratch_root(tmp_path):
    """Return a scratch repository root with the real folders linked in."""
    root = tmp_path / 'root'
    root.mkdir()
    for name in LINKED:
        if os.path.exists(os.path.join(ROOT, name)):
            os.symlink(os.path.join(ROOT, name), root / name)
    return root


def _env(page):
    env = ros_env(domain_id(13 + PAGES.index(page)))
    env.pop('MAKEFLAGS', None)
    env.pop('MAKELEVEL', None)
    return env


def _command(lang, text, cwd):
    if RUN[lang] == 'python':
        path = os.path.join(cwd, '_doc_block.py')
        with open(path, 'w', encoding='utf-8') as fh:
            fh.write(text)
        return [sys.executable, path]
    return ['bash', '-e', '-o', 'pipefail', '-c', text]


def _check_well_formed(where, lang, text):
    if RUN[lang] == 'python':
        compile(text, where, 'exec')
        return
    res = subprocess.run(['bash', '-n', '-c', text], capture_output=True,
                         text=True)
    assert res.returncode == 0, f'{where}: not valid bash: {res.stderr}'


def _stop_after(proc, seconds, where):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.2)
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
    try:
        out, _ = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        raise AssertionError(f'{where}: did not stop on SIGINT:\n{out[-3000:]}')
    return proc.returncode, out


STOP_AT = re.compile(r'stop at "([^"]+)" \(at most (\d+(?:\.\d+)?) s\)$')
SETTLE = 1.0    # seconds between the ready line and SIGINT


def _stop_at(proc, text, seconds, where):
    """Stop ``proc`` a moment after it prints ``text``; (status, output)."""
    lines, seen = [], threading.Event()

    def read():
        for line in proc.stdout:
            lines.append(line)
            if text in line:
                seen.set()
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    deadline = time.monotonic() + seconds
    while (not seen.is_set() and proc.poll() is None
           and time.monotonic() < deadline):
        seen.wait(0.1)
    if seen.is_set() and proc.poll() is None:
        time.sleep(SETTLE)
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        reader.join(5)
        raise AssertionError(f'{where}: did not stop on SIGINT:\n'
                             f'{"".join(lines)[-3000:]}')
    reader.join(5)
    out = ''.join(lines)
    if proc.returncode == 0:
        assert seen.is_set(), (f'{where}: no line with {text!r} within '
                               f'{seconds} s:\n{out[-3000:]}')
    return proc.returncode, out


def run_page(page, cwd, passed=None):
    """
    Run every block of one page in order; return how many ran.

    ``passed``: the texts of the blocks that already ran and passed in
    ``cwd`` (pages share one root in the suite: the README and the
    identification pages run the same commands on the same files, and an
    identical command is run once); each block run here is added.
    """
    ran = 0
    env = _env(page)
    passed = set() if passed is None else passed
    for line, lang, directive, text in blocks(page):
        if lang not in RUN or RUN[lang] is None:
            continue
        where = f'{page}:{line}'
        if RUN[lang] == 'bash':
            bad = re.search(r'\s\[--?[\w-]+[^\]]*\]', text)
            assert not bad, (f'{where}: usage notation {bad.group(0)!r} in a '
                             'bash block: put synopses in a text block')
        _check_well_formed(where, lang, text)
        if directive and directive.startswith('skip'):
            assert re.match(r'skip \(.+\)', directive), (
                f'{where}: a skipped block must say why: skip (REASON)')
            continue
        if text in passed:
            continue
        started = time.monotonic()
        proc = subprocess.Popen(
            _command(lang, text, str(cwd)), cwd=str(cwd), env=env,
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            start_new_session=True, stdin=subprocess.DEVNULL)
        m = re.match(r'stop after (\d+(?:\.\d+)?) s', directive or '')
        at = STOP_AT.match(directive or '')
        if m:
            code, out = _stop_after(proc, float(m.group(1)), where)
        elif at:
            code, out = _stop_at(proc, at.group(1), float(at.group(2)),
                                 where)
        else:
            assert directive is None, f'{where}: unknown directive {directive!r}'
            try:
                out, _ = proc.communicate(timeout=BLOCK_TIMEOUT)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                out, _ = proc.communicate()
                raise AssertionError(
                    f'{where}: still running after {BLOCK_TIMEOUT} s:\n'
                    f'{out[-3000:]}')
            code = proc.returncode
        assert code == 0, (f'{where}: exit status {code} for\n{text}\n'
                           f'output:\n{out[-4000:]}')
        _log_time(where, time.monotonic() - started)
        passed.add(text)
        ran += 1
    return ran


def _log_time(where, seconds):
    """Append one block's wall time to build/doc_block_seconds.txt."""
    path = os.path.join(ROOT, 'build', 'doc_block_seconds.txt')
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, 'a', encoding='utf-8') as fh:
            fh.write(f'{seconds:8.1f}  {where}\n')
    except OSError:
        pass                            # a record, not a check


def test_pages_are_found():
    assert 'README.md' in PAGES and len(PAGES) > 3, PAGES


def test_block_parser_reads_directives():
    text = blocks('README.md')
    assert text and all(lang is not None for _, lang, _, _ in text)


@pytest.fixture(scope='module')
def shared_root(tmp_path_factory):
    """One scratch root for every page, and the blocks passed in it."""
    return scratch_root(tmp_path_factory.mktemp('pages')), set()


@pytest.mark.slow
@pytest.mark.parametrize('page', PAGES)
def test_every_command_on_the_page_works_as_pasted(page, shared_root):
    root, passed = shared_root
    run_page(page, root, passed)


def _page(name):
    with open(os.path.join(ROOT, name), encoding='utf-8') as fh:
        return fh.read()


NODE_PAGES = {'inverse_dynamics_node': 'docs/node.md',
              'mujoco_sim_node': 'docs/node.md',
              'robot_sim_node': 'docs/scenes-and-demos.md',
              'tracking_controller_node': 'docs/scenes-and-demos.md'}


@pytest.mark.parametrize('node', sorted(NODE_PAGES))
def test_every_parameter_table_is_the_schema_output(node):
    from newton_euler_ros.parameters import load_specs, markdown_table
    table = markdown_table(load_specs(node))
    assert table in _page(NODE_PAGES[node]), (
        f'{NODE_PAGES[node]}: paste the output of .venv/bin/python -m '
        f'newton_euler_ros.parameters --markdown {node}')


@pytest.mark.parametrize('node', sorted(NODE_PAGES))
def test_every_topic_and_service_of_the_node_is_documented(node):
    path = os.path.join(ROOT, 'newton_euler_ros', 'newton_euler_ros',
                        'nodes', f'{node}.py')
    with open(path, encoding='utf-8') as fh:
        source = fh.read()
    names = set(re.findall(
        r"create_(?:subscription|publisher|service)\(\s*\w+,\s*'([^']+)'",
        source))
    assert names, f'no topics found in {path}'
    page = _page(NODE_PAGES[node])
    missing = sorted(n for n in names if f'`{n}`' not in page)
    assert not missing, f'{NODE_PAGES[node]} does not list {missing}'
