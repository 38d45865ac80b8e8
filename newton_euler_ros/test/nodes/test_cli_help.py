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
``newton-euler COMMAND --help`` and docs/cli.md's synopses agree.

The options come from each command's argument parser (whatever it has
when the test runs), the synopses from the ``text`` block of docs/cli.md
that lists ``newton-euler COMMAND ...`` lines: every command has a
synopsis; its positional arguments are the parser's, in order and by the
names ``--help`` shows; every option of the parser is in it under one of
its spellings, with a value placeholder exactly when it takes a value,
and it names no option the parser lacks.  Every positional argument
and every command has help text.  Each node's ``--help`` names its
reference page, which exists and documents its parameters.
"""
import argparse
import os
import re
import subprocess
import sys

from newton_euler_ros.cli import build_parser
from newton_euler_ros.parameters import (load_specs, markdown_table,
                                         node_help, NODE_PAGES, NODES)
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
CLI_PAGE = os.path.join(ROOT, 'docs', 'cli.md')


def subcommands():
    """Return {name: (parser, help)} of every newton-euler command."""
    parser = build_parser()
    sub = next(a for a in parser._actions
               if isinstance(a, argparse._SubParsersAction))
    helps = {a.dest: a.help for a in sub._choices_actions}
    return {name: (p, helps.get(name)) for name, p in sub.choices.items()}


def synopses():
    """Return {command: [tokens]} from docs/cli.md's synopsis block."""
    with open(CLI_PAGE, encoding='utf-8') as fh:
        text = fh.read()
    blocks = [b for b in re.findall(r'```text\n(.*?)```', text, re.S)
              if b.startswith('newton-euler ')]
    assert len(blocks) == 1, 'docs/cli.md: one ```text block of synopses'
    out = {}
    command = None
    for line in blocks[0].splitlines():
        words = line.replace('[', ' ').replace(']', ' ').split()
        if not words:
            continue
        if words[0] == 'newton-euler':
            command = words[1]
            assert command not in out, f'two synopses of {command}'
            out[command] = words[2:]
        else:
            out[command] += words
    return out


def is_option(token):
    return re.fullmatch(r'--?[A-Za-z][\w-]*', token) is not None


COMMANDS = subcommands()
SYNOPSES = synopses()


def test_every_command_has_one_synopsis_and_no_other():
    assert sorted(SYNOPSES) == sorted(COMMANDS)


@pytest.mark.parametrize('command', sorted(COMMANDS))
def test_synopsis_lists_the_parsers_options(command):
    parser, _ = COMMANDS[command]
    tokens = SYNOPSES[command]
    actions = [a for a in parser._actions
               if not isinstance(a, argparse._HelpAction)]
    # positional arguments: before the first option, by their --help names
    first = next((i for i, t in enumerate(tokens) if is_option(t)),
                 len(tokens))
    positionals = []
    for a in actions:
        if not a.option_strings:      # X, or X [X ...] for several
            name = a.metavar or a.dest
            positionals += ([name, name, '...'] if a.nargs == '+'
                            else [name])
    assert tokens[:first] == positionals, (command, tokens[:first])
    takes_value = {}
    for action in actions:
        for spelling in action.option_strings:
            takes_value[spelling] = action.nargs != 0
    listed = {}
    for i, token in enumerate(tokens):
        if is_option(token):
            nxt = tokens[i + 1] if i + 1 < len(tokens) else ''
            listed[token] = bool(nxt) and not nxt.startswith('-')
    unknown = sorted(set(listed) - set(takes_value))
    assert not unknown, f'docs/cli.md: {command}: no such option {unknown}'
    for action in actions:
        if not action.option_strings:
            continue
        shown = [s for s in action.option_strings if s in listed]
        assert shown, (f'docs/cli.md: the {command} synopsis lacks '
                       f'{"/".join(action.option_strings)}')
        for spelling in shown:
            assert listed[spelling] == takes_value[spelling], (
                f'docs/cli.md: {command} {spelling} '
                f'{"takes" if takes_value[spelling] else "takes no"} value')


@pytest.mark.parametrize('command', sorted(COMMANDS))
def test_every_positional_and_command_has_help(command):
    parser, summary = COMMANDS[command]
    assert summary, f'{command} has no help line in newton-euler --help'
    for action in parser._actions:
        if not action.option_strings:
            assert action.help, (command, action.metavar or action.dest)


def test_help_runs_for_every_command():
    exe = os.path.join(os.path.dirname(sys.executable), 'newton-euler')
    proc = subprocess.run([exe, '--help'], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    for command in COMMANDS:
        assert f'    {command}' in proc.stdout, command
    proc = subprocess.run([exe, 'identify', '--help'], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0 and 'NOMINAL.urdf BAG' in proc.stdout


@pytest.mark.parametrize('node', NODES)
def test_node_help_names_its_page_and_the_page_exists(node):
    text = node_help(node)
    pages = set(re.findall(r'\b(docs/[\w.-]+\.md|README\.md)', text))
    assert NODE_PAGES[node] in pages, text[:600]
    for page in pages:
        assert os.path.isfile(os.path.join(ROOT, page)), page
    assert 'README ("' not in text           # a section that is gone
    with open(os.path.join(ROOT, NODE_PAGES[node]), encoding='utf-8') as fh:
        assert markdown_table(load_specs(node)) in fh.read()


def test_help_and_usage_errors_load_no_dynamics():
    """
    ``--help`` and a usage error answer without numba or the kernels.

    They are what a user types first and most often: the dynamics load
    where a command first uses them (1.4 s of a 1.7 s ``--help`` before).
    """
    code = '\n'.join((
        'import contextlib, io, sys',
        'from newton_euler_ros import cli',
        'for argv in sys.argv[1:]:',
        '    out = io.StringIO()',
        '    with contextlib.redirect_stdout(out), '
        'contextlib.redirect_stderr(out):',
        '        try:',
        '            status = cli.main(argv.split())',
        '        except SystemExit as exc:',
        '            status = exc.code',
        '    print(argv, status, out.getvalue().count("\\n"))',
        'loaded = sorted(m for m in sys.modules if m == "numba" or',
        '                m.startswith("newton_euler_ros.core.kernels"))',
        'print("loaded:", loaded)'))
    argvs = ['--help', 'frobnicate'] + [f'{c} --help' for c in COMMANDS] \
        + ['dynamics', 'identify', 'observe a b --rate x']
    proc = subprocess.run([sys.executable, '-c', code, *argvs],
                          capture_output=True, text=True, timeout=120)
    lines = proc.stdout.splitlines()
    assert proc.returncode == 0 and lines[-1] == 'loaded: []', (
        proc.stdout[-2000:] + proc.stderr[-2000:])
    statuses = dict(line.rsplit(' ', 2)[:2] for line in lines[:-1])
    assert statuses['--help'] == '0' and statuses['identify --help'] == '0'
    assert statuses['frobnicate'] == '2' and statuses['identify'] == '2'
    assert statuses['dynamics'] == '2', statuses
    assert statuses['observe a b --rate x'] == '2', statuses


def test_the_core_names_load_on_first_use():
    """Every name of ``core.__all__`` resolves; reading errors loads none."""
    code = '\n'.join((
        'import sys',
        'import newton_euler_ros.core as core',
        'from newton_euler_ros.core import NewtonEulerError',
        'assert "numba" not in sys.modules, "errors alone loaded numba"',
        'assert sorted(core.__all__) == sorted(core._WHERE), "__all__"',
        'for name in core.__all__:',
        '    value = getattr(core, name)',
        '    assert getattr(value, "__name__", name) == name, name',
        'assert set(core.__all__) <= set(dir(core))',
        'try:',
        '    core.no_such_name',
        'except AttributeError as exc:',
        '    print(exc)',
        'from newton_euler_ros.core import *',
        'print(inverse_dynamics.__module__)'))
    proc = subprocess.run([sys.executable, '-c', code], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.splitlines() == [
        "module 'newton_euler_ros.core' has no attribute 'no_such_name'",
        'newton_euler_ros.core.dynamics'], proc.stdout
