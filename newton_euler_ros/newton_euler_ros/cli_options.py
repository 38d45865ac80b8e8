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
Argument groups that several ``newton-euler`` commands share.

One definition each for the robot argument, the URDF argument of the
commands that take only a URDF, the chain options of a command that
also takes a robot YAML, the chain and recording options of the
commands that read a recording (identify, replay, payload), the
JointState topic, and the --json and --overwrite switches, so that the
same option reads the same in every command's ``--help``.  Imports
nothing heavy: ``cli`` builds its parser from these before any command
runs.
"""
ROBOT_HELP = 'robot YAML or URDF file, or bundled robot name'
TOPIC_HELP = 'JointState topic (default /joint_states)'


def robot_argument(parser):
    """Add the positional ROBOT: a file or a bundled robot's name."""
    parser.add_argument('robot', metavar='ROBOT', help=ROBOT_HELP)


def model_argument(parser, model_help):
    """Add the positional MODEL.urdf (``args.model``): ``model_help``."""
    parser.add_argument('model', metavar='MODEL.urdf', help=model_help)


def chain_options(parser, tip_help):
    """Add --base and --tip (``tip_help``) for a URDF's chain."""
    parser.add_argument('--base', metavar='LINK',
                        help='URDF only: first link of the chain (default: '
                             'the root link)')
    parser.add_argument('--tip', metavar='LINK', help=tip_help)


def topic_option(parser):
    """Add --topic, the JointState topic (default /joint_states)."""
    parser.add_argument('--topic', default='/joint_states',
                        help=TOPIC_HELP)


def recording_options(parser, tip_help, cutoff_help):
    """
    Add the options of a command fitting a URDF to a recording.

    --base (required: the tree's root is rarely the arm's base), --tip
    (``tip_help``), --topic and --cutoff (``cutoff_help``).
    """
    parser.add_argument('--base', metavar='LINK', required=True,
                        help='first link of the chain, or the link the '
                             'whole tree hangs from')
    parser.add_argument('--tip', metavar='LINK', help=tip_help)
    topic_option(parser)
    parser.add_argument('--cutoff', type=float, metavar='HZ',
                        help=cutoff_help)


def json_option(parser, json_help):
    """Add --json: print the result as JSON (``json_help``: what)."""
    parser.add_argument('--json', action='store_true', help=json_help)


def overwrite_option(parser, overwrite_help):
    """Add --overwrite: write over an existing file (``overwrite_help``)."""
    parser.add_argument('--overwrite', action='store_true',
                        help=overwrite_help)
