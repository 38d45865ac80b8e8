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
Compiled kernels: the derivation's passes, one file each.

=====================  ====================================================
file                   what it holds
=====================  ====================================================
``newton_euler.py``    the Newton-Euler recursion: the forward pass (base
                       to tip: velocities, accelerations, each link's net
                       force and moment) and the backward pass (tip to
                       base: the force balance, the joint torques), with
                       the tip wrench beside them; g(q); D and C column by
                       column from unit inputs
``momentum.py``        D qd, C^T qd and g in one recursion (the momentum
                       observer's terms)
``crba.py``            D(q) by the composite-rigid-body algorithm
``coriolis.py``        C(q, qd) in O(n^2) from composite bodies
``aba.py``             qdd by the articulated-body algorithm
``derivatives.py``     dtau/dq, dtau/dqd and dqdd/d(q, qd, tau),
                       analytically, from the composite-body passes
``kinematics.py``      the tree (parents, branch points, mimic joints'
                       coordinates), joint placements, link poses, spatial
                       inertias and the Jacobian of any link
``spatial.py``         3-vector and 6x6 helpers; the one force carry
                       (``force_to_parent``) and the one motion carry
                       (``motion_to_child``)
``regressor.py``       the joint-torque regressor Y (tau = Y pi) and its
                       drive columns
``cholesky.py``        Cholesky solve
``status.py``          finiteness checks and status codes in the kernels
``layout.py``          every array column by name, each array's columns
                       one declaration (``LINKS``: ``L_*``; ``WS``: ``W_*``;
                       ``AW``, ``CW``, ``DW``, ...), flags, status codes
``entry.py``           each term once, as its row step, and the table of
                       entry points (``ENTRIES``)
``entries.py``         what Python calls: the entry points and batch loops
                       (size and finiteness checks, the loop), GENERATED
                       from ``entry.py`` by ``generate.py`` and checked in
                       (``entries_derivatives.py``: the derivatives)
``generate.py``        writes ``entries.py`` (``python -m
                       newton_euler_ros.core.kernels.generate --write``)
``_jit.py``            ``njit``, the entry options, on-disk caching
=====================  ====================================================

Everything is scalar code over 3-tuples so that numba compiles it to tight
machine code, and so that the very same source runs in plain Python on
other number types (:func:`load_copy`: the 50-digit reference runs these
files with ``njit`` replaced by the identity).  Nothing allocates in the
hot path: callers pass workspace arrays.

Number types.  The kernels are generic in the dtype of the arrays they
are given: they contain no float literal (numba types one as float64, and
float32 op float64 is float64), taking 0, 1/2 and 1 from the constants
row ``frames[F_CONST]`` instead, and comparing with integer literals only.
So float64 arrays give float64 arithmetic, float32 arrays float32
arithmetic throughout (``core.float32``; the tests check numba's type
maps), and mpf object arrays mpmath arithmetic (``core.highprec``).
"""
import os
import sys
import types

from . import entries as _entries
from . import entries_derivatives as _entries_derivatives
from ._jit import ENTRY, package_locators
from .aba import articulated_body
from .cholesky import cholesky_solve
from .coriolis import coriolis_matrix_composite
from .crba import mass_matrix_crba
from .kinematics import forward_kinematics, jacobian, joint_trig
from .layout import (A_A, A_C, A_D, A_IA, A_PA, A_U, A_UU, A_V, A_WIDTH, AW,
                     C_HALF, C_ONE, C_ZERO, Columns, CONST, CONSTANTS, CS,
                     CS_BC, CS_H, CS_IC, CW, CW_BCA, CW_F1, CW_F2, CW_G, CW_I,
                     CW_ICA, CW_OW, CW_RW, CW_S, CW_SD, CW_V, CW_WIDTH,
                     DECLARATIONS, DS, DW, DW_WIDTH, F_BASE, F_CONST, F_GRAV,
                     F_ROWS, F_TOOL, F_TREE, flags, FRAMES, GRAVITY, L_BODY,
                     L_COM, L_INERTIA, L_LEAD, L_MASS, L_MULT, L_OFFSET, L_P,
                     L_PARENT, L_R, L_STORE, L_TYPE, L_WIDTH, LINK_WRENCHES,
                     LINKS, MIMIC, NONFINITE, OVERFLOW, pack, SINGULAR, SIZE,
                     T_BRANCHED, T_NQ, T_TOOL, TREE, VELOCITY, W_ACC, W_CT,
                     W_DD, W_F, W_N, W_P, W_R, W_ST, W_WIDTH, W_X, WRENCH_BASE,
                     WRENCH_BITS, WRENCH_EE, WRENCH_NONE, WRENCH_SHIFT, WS)
from .momentum import momentum_terms
from .newton_euler import (coriolis_matrix_columns, mass_matrix_columns,
                           recursion, unit_columns)
from .status import check_finite, first_nonfinite, round_into

__all__ = [
    'AW', 'Columns', 'CONST', 'CS', 'CW', 'DECLARATIONS', 'DS', 'DW',
    'FRAMES', 'LINKS', 'TREE', 'WS',
    'A_A', 'A_C', 'A_D', 'A_IA', 'A_PA', 'A_U', 'A_UU', 'A_V', 'A_WIDTH',
    'articulated_body', 'C_HALF', 'C_ONE', 'C_ZERO', 'check_finite',
    'cholesky_solve', 'CONSTANTS', 'coriolis_matrix_columns',
    'coriolis_matrix_composite', 'CS_BC', 'CS_H', 'CS_IC', 'CW_BCA',
    'CW_F1', 'CW_F2', 'CW_G', 'CW_I', 'CW_ICA', 'CW_OW', 'CW_RW', 'CW_S',
    'CW_SD', 'CW_V', 'CW_WIDTH', 'DW_WIDTH', 'ENTRY', 'F_BASE', 'F_CONST',
    'F_GRAV',
    'F_ROWS', 'F_TOOL', 'F_TREE', 'first_nonfinite', 'flags',
    'forward_kinematics', 'GRAVITY', 'jacobian', 'joint_trig', 'L_BODY',
    'L_COM', 'L_INERTIA', 'L_LEAD', 'L_MASS', 'L_MULT', 'L_OFFSET', 'L_P',
    'L_PARENT', 'L_R', 'L_STORE', 'L_TYPE', 'L_WIDTH', 'LINK_WRENCHES',
    'mass_matrix_columns', 'mass_matrix_crba', 'MIMIC', 'momentum_terms',
    'NONFINITE', 'OVERFLOW', 'pack', 'package_locators', 'recursion',
    'round_into', 'SINGULAR',
    'SIZE', 'T_BRANCHED', 'T_NQ', 'T_TOOL', 'unit_columns', 'VELOCITY',
    'W_ACC', 'W_CT', 'W_DD', 'W_F', 'W_N', 'W_P', 'W_R', 'W_ST', 'W_WIDTH',
    'W_X', 'WRENCH_BASE', 'WRENCH_BITS', 'WRENCH_EE', 'WRENCH_NONE',
    'WRENCH_SHIFT',
]

# every entry point of entries*.py (``run_<term>``, ``run_<term>_batch``):
# a line in entry.ENTRIES, then regenerating, is all it takes to export it
RUN = {name: f for module in (_entries, _entries_derivatives)
       for name, f in vars(module).items() if name.startswith('run_')}
globals().update(RUN)
__all__ += sorted(RUN)

# the kernel files in the order they import each other
MODULES = ('_jit', 'layout', 'spatial', 'status', 'cholesky', 'kinematics',
           'newton_euler', 'momentum', 'crba', 'coriolis', 'aba',
           'derivatives', 'regressor', 'entry', 'entries',
           'entries_derivatives')
_DIR = os.path.dirname(os.path.abspath(__file__))


def load_copy(tag, decorator, math_module=None):
    """
    Run the kernel files again as a separate package; return its namespace.

    ``decorator`` replaces ``njit`` (called as ``njit(f)`` or
    ``njit(**options)``); ``math_module``, if given, replaces ``math`` in
    every file.  The copy is registered as
    ``newton_euler_ros.core.kernels_<tag>`` so that the files' relative
    imports find each other's copies; the returned module holds every
    name of every file (for ``copy.recursion`` and the like).
    """
    name = f'{__name__}_{tag}'
    package = types.ModuleType(name)
    package.__path__ = []
    sys.modules[name] = package
    flat = types.ModuleType(name + '.flat')
    for sub in MODULES:
        module = types.ModuleType(f'{name}.{sub}')
        module.__package__ = name
        module.__file__ = os.path.join(_DIR, sub + '.py')
        if sub == '_jit':
            module.__dict__['__njit_override__'] = decorator
        sys.modules[module.__name__] = module
        with open(module.__file__, encoding='utf-8') as fh:
            code = compile(fh.read(), module.__file__, 'exec')
        exec(code, module.__dict__)  # noqa: S102 - our own source files
        if math_module is not None and 'math' in module.__dict__:
            module.__dict__['math'] = math_module
        setattr(package, sub, module)
        for key, value in vars(module).items():
            if not key.startswith('__'):
                setattr(flat, key, value)
    return flat
