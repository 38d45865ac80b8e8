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
``newton-euler export``: an identified URDF's inertials for a description.

    newton-euler export MODEL.urdf --format ur|franka -o OUT.yaml
                        [--template ORIGINAL.yaml] [--prefix PREFIX]
                        [--overwrite]

``ur`` writes ur_description's ``physical_parameters.yaml`` (with
``--template``, the robot's published file, whose other fields are
kept), ``franka`` franka_description's ``inertials.yaml``
(``ident.export`` says which fields and in which axes).  A bad input is
one line on stderr and exit status 2; the output is written atomically
and an existing one only with ``--overwrite``.
"""
import sys

from .cli_options import model_argument, overwrite_option

# ident.export.FORMATS (test_export checks they agree): the identification
# package is imported only when a command of it runs, never by `cli`
FORMATS = ('ur', 'franka')


def cmd_export(args):
    """Run ``newton-euler export``."""
    from .ident.export import export
    note = export(args.model, args.format, args.output,
                  template=args.template, prefix=args.prefix,
                  overwrite=args.overwrite)
    print(f'note: {note}', file=sys.stderr)
    print(f'wrote {args.output}')
    return 0


def register(subparsers):
    """Add the ``export`` command to ``subparsers``."""
    exp = subparsers.add_parser(
        'export', help="write an identified URDF's inertials as UR's "
                       "physical_parameters.yaml or Franka's inertials.yaml")
    model_argument(exp, 'the identified URDF (newton-euler identify -o)')
    exp.add_argument('--format', required=True, choices=FORMATS,
                     help="ur: ur_description's physical_parameters.yaml; "
                          "franka: franka_description's inertials.yaml")
    exp.add_argument('-o', '--output', metavar='OUT.yaml', required=True,
                     help='the YAML file to write')
    exp.add_argument('--template', metavar='ORIGINAL.yaml',
                     help='(ur) the published physical_parameters.yaml: its '
                          'offsets, base_mass, radii, links and rotations '
                          'are kept (without it only inertia_parameters is '
                          'written)')
    exp.add_argument('--prefix', metavar='PREFIX',
                     help="the links' name prefix (ur's tf_prefix, e.g. "
                          "'fr3_' or 'panda_'; default: the one naming "
                          'every link needed)')
    overwrite_option(exp, 'replace OUT.yaml if it exists')
    exp.set_defaults(func=cmd_export)
