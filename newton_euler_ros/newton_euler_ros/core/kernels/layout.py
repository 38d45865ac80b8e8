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
The kernels' array layouts: every column and row by name, declared once.

The kernels take a robot as two arrays, ``links`` (one row per joint) and
``frames`` (fixed frames and constants), and write into workspace arrays
(``ws``, ``aw``, ``cw``, ``dw``) owned by a
:class:`~newton_euler_ros.core.Workspace`.  numba wants plain 2-D arrays;
these names are how the code addresses them: a field of width k starts at
its column and takes k consecutive ones (a 3x3 matrix is 9 columns
row-major, a 6x6 one 36).

Each array's columns are one ordered declaration (:class:`Columns`): a
line ``L_COM = LINKS.add('com', 3, '...')`` declares the field ``com`` of
``links``, 3 columns wide, and binds its first column to ``L_COM``; the
offsets and the width (``L_WIDTH = LINKS.width``) follow from the order,
so a new quantity is one line where it belongs, and nothing is numbered
by hand.  The names are plain module-level ints, which numba reads as
constants: the compiled code is what hand-numbered columns gave.
:meth:`Columns.row` fills a row by field names (``core.tree``), and
``test_layout.py`` checks that every ``L_*`` (and the others) is declared
and that every constant offset the kernels add stays inside its field.

The package :mod:`newton_euler_ros.core.kernels` re-exports the names
its callers use (``from newton_euler_ros.core.kernels import L_MASS,
F_GRAV``); ``W_R0`` and the derivative workspaces' ``DW_*`` and
``DS_*`` fields, which only the kernels read, are imported from here.
"""


class Columns:
    """
    An array's columns as one ordered declaration: name, width, meaning.

    ``prefix`` is the prefix of the module-level names (``'L_'``): field
    ``com`` is bound to ``L_COM``.  Each :meth:`add` returns the field's
    first column, the sum of the widths declared before it.
    """

    def __init__(self, prefix, what):
        self.prefix = prefix
        self.what = what
        self.fields = []        # (name, offset, width, meaning), in order
        self.width = 0

    def add(self, name, width, meaning):
        """Declare field ``name`` of ``width`` columns; return its offset."""
        if width < 1 or any(f[0] == name for f in self.fields):
            raise ValueError(f'{self.what}: field {name!r} declared twice '
                             f'or of width {width}')
        offset = self.width
        self.fields.append((name, offset, width, meaning))
        self.width += width
        return offset

    def constant(self, name):
        """Return the module-level name of field ``name`` (``L_COM``)."""
        return self.prefix + name.upper()

    def offsets(self):
        """Return {module-level name: (offset, width)} of every field."""
        return {self.constant(name): (offset, width)
                for name, offset, width, _ in self.fields}

    def row(self, zero, **values):
        """
        Return a row filled by field names: a list of ``width`` numbers.

        Every declared field must be given, a scalar for a field of width
        1, else a sequence of its width; a missing, unknown or wrong-width
        field raises ValueError naming it.
        """
        row = [zero] * self.width
        for name, offset, width, _ in self.fields:
            if name not in values:
                raise ValueError(f'{self.what}: field {name!r} '
                                 f'({self.constant(name)}, {width} '
                                 f'column(s)) is not given')
            value = values.pop(name)
            if width == 1 and not isinstance(value, (list, tuple)):
                value = [value]
            try:
                value = list(value)
            except TypeError:
                value = [value]
            if len(value) != width:
                raise ValueError(f'{self.what}: field {name!r} '
                                 f'({self.constant(name)}) takes {width} '
                                 f'value(s), got {len(value)}')
            row[offset:offset + width] = value
        if values:
            raise ValueError(f'{self.what}: no field(s) '
                             f'{", ".join(sorted(values))} declared')
        return row


# ---- ``links``: one row per moving joint (body), in kernel frames -------
# (see ``tree.compile_arrays``).  The bodies form a tree numbered so that
# a parent comes before its children: the parent of body j is body
# lambda(j) < j, or the base (-1); a chain has lambda(j) = j - 1.  Kernel
# frame j is kernel frame lambda(j) moved by the constant placement
# (R, p), then by Rz(q_j) (revolute) or Tz(q_j) (prismatic).  The joint
# axis is z of kernel frame j and passes through its origin.  A mimic
# joint has no coordinate of its own: its angle is mult * q[lead] + offset
# (an independent joint: lead its own coordinate, mult 1, offset 0).
LINKS = Columns('L_', 'links row')
L_TYPE = LINKS.add('type', 1, '0.0 revolute, 1.0 prismatic')
L_R = LINKS.add('r', 9, 'placement rotation in kernel frame lambda(j), '
                'row-major')
L_P = LINKS.add('p', 3, 'placement origin in kernel frame lambda(j)')
L_MASS = LINKS.add('mass', 1, 'the link mass')
L_COM = LINKS.add('com', 3, 'centre of mass, kernel frame j')
L_INERTIA = LINKS.add('inertia', 9, 'inertia about the com in kernel-frame '
                      'axes, row-major')
L_BODY = LINKS.add('body', 12, 'R (9, row-major) then p (3) of link frame j '
                   'in kernel frame j')
L_PARENT = LINKS.add('parent', 1, 'lambda(j), the parent body (-1.0: the '
                     'base)')
L_LEAD = LINKS.add('lead', 1, 'the coordinate (index into q) that moves '
                   'joint j')
L_MULT = LINKS.add('mult', 1, 'its multiplier (1.0 for an independent '
                   'joint)')
L_OFFSET = LINKS.add('offset', 1, 'its offset (0.0 for an independent '
                     'joint)')
L_STORE = LINKS.add('store', 1, '1.0 when a child of j is not j + 1: the '
                    "passes keep j's state in the workspace for it (a "
                    'branch point)')
L_WIDTH = LINKS.width

# ---- ``frames``: rows of fixed frames, shape (F_ROWS, 12) ----------------
FRAMES = Columns('F_', 'frames rows')
F_BASE = FRAMES.add('base', 1, 'R (9, row-major) then p (3): DH frame 0 in '
                    'the base frame')
F_TOOL = FRAMES.add('tool', 1, 'end-effector frame in the last link frame')
F_GRAV = FRAMES.add('grav', 1, 'first 3 entries: gravity in frame-0 axes')
F_CONST = FRAMES.add('const', 1, "the constants C_*, in the arrays' own "
                     'number type')
F_TREE = FRAMES.add('tree', 1, "the tree's shape, the T_* columns")
F_ROWS = FRAMES.width

# Columns of the tree row ``frames[F_TREE]`` (integers, in the arrays'
# number type).
TREE = Columns('T_', 'tree row')
T_NQ = TREE.add('nq', 1, 'the number of coordinates n (independent '
                'joints)')
T_TOOL = TREE.add('tool', 1, 'the body carrying the end-effector frame (-1: '
                  'the base)')
T_BRANCHED = TREE.add('branched', 1, "1 when some body's parent is not the "
                      'body before it')

# Columns of the constants row ``frames[F_CONST]``.  A float literal in
# numba code is a float64, and float32 op float64 is float64: the kernels
# take every constant from this row so that they compute purely in the
# dtype of the arrays they are given (float64, float32, or mpmath's mpf).
CONST = Columns('C_', 'constants row')
C_ZERO = CONST.add('zero', 1, '0.0')
C_HALF = CONST.add('half', 1, '0.5')
C_ONE = CONST.add('one', 1, '1.0')
CONSTANTS = (0.0, 0.5, 1.0)     # their values, in that order

# ---- ``ws``: the per-joint workspace of every pass (n rows) --------------
WS = Columns('W_', 'ws row')
W_R = WS.add('r', 9, 'rotation of kernel frame j in kernel frame j-1')
W_P = WS.add('p', 3, 'origin of kernel frame j in kernel frame j-1')
W_F = WS.add('f', 3, 'net force on link j (m a_c), Newton-Euler')
W_N = WS.add('n', 3, 'net moment about the com, Newton-Euler')
W_CT = WS.add('ct', 1, 'cos(q_j) (1 for a prismatic joint)')
W_ST = WS.add('st', 1, 'sin(q_j) (0 for a prismatic joint)')
W_DD = WS.add('dd', 1, 'q_j for a prismatic joint (0 for a revolute one)')
W_X = WS.add('x', 24, "a branch point's state for its children (each pass "
             'its own: velocities, accelerations, poses)')
W_ACC = WS.add('acc', 12, "what a branch point's children carried back to "
               'it (wrenches, composite bodies), summed')
W_R0 = WS.add('r0', 9, 'rotation of kernel frame j in the base frame (link '
              'wrenches in base axes)')
W_WIDTH = WS.width

# ---- ``aw``: the articulated-body workspace (n + 1 rows; row n scratch) --
# Spatial vectors are [angular; linear] (motion) or [moment; force]
# (force) at the origin of the frame whose axes they are in.
AW = Columns('A_', 'aw row')
A_IA = AW.add('ia', 36, 'articulated inertia of link j about O_j, frame j')
A_PA = AW.add('pa', 6, 'articulated bias force')
A_V = AW.add('v', 6, 'spatial velocity of link j')
A_C = AW.add('c', 6, 'velocity-product acceleration v_j x (S_j qd_j)')
A_U = AW.add('u', 6, 'U = IA S (the column of IA on the joint axis)')
A_D = AW.add('d', 1, 'd = S^T IA S, the articulated inertia on the axis')
A_UU = AW.add('uu', 1, 'u = tau - S^T pA')
A_A = AW.add('a', 6, 'spatial acceleration of a branch point')
A_WIDTH = AW.width

# ---- ``cw``: the composite Coriolis workspace (n + 1 rows) ---------------
# Row n is scratch: its columns are CS below.
CW = Columns('CW_', 'cw row')
CW_S = CW.add('s', 6, 'motion subspace of joint j, frame 0 at its origin')
CW_SD = CW.add('sd', 6, 'its rate, V_j x S_j')
CW_F1 = CW.add('f1', 6, 'IC_j S_j')
CW_F2 = CW.add('f2', 3, 'BC_j^T S_j: its angular part (the linear is zero)')
CW_G = CW.add('g', 6, 'IC_j Sdot_j + BC_j S_j')
CW_RW = CW.add('rw', 9, 'rotation of kernel frame j in frame 0')
CW_OW = CW.add('ow', 3, 'origin of kernel frame j in frame 0')
CW_V = CW.add('v', 6, 'spatial velocity of link j')
CW_I = CW.add('i', 10, 'spatial inertia of link j, frame 0 about its origin '
              '(``coriolis.inertia_times``): J (xx, xy, xz, yy, yz, zz), '
              'h = m c, m')
CW_ICA = CW.add('ica', 10, 'composite inertia the children of a branch '
                'point carried back to it (summed)')
CW_BCA = CW.add('bca', 12, 'the same of their composite Coriolis matrices')
CW_WIDTH = CW.width
CS = Columns('CS_', 'cw scratch row')
CS_IC = CS.add('ic', 10, 'composite inertia, as ``CW_I``')
CS_BC = CS.add('bc', 12, 'composite Coriolis matrix [[P, 0], [-[h_f], 0]]: '
               'P (9, row-major), then h_f')
CS_H = CS.add('h', 6, 'I_j V_j')

# ---- ``dw``: the derivative workspace (n + 1 rows) -------------------------
# Spatial vectors in frame 0 about its origin, as in ``cw`` (derivatives.py).
# Row n is scratch: its columns are DS below.
DW = Columns('DW_', 'dw row')
DW_A = DW.add('a', 6, 'spatial acceleration of link j, gravity as the '
              "base's")
DW_C = DW.add('c', 6, 'c_j = S_j x A_lambda(j) + Sdot_j x V_lambda(j)')
DW_E = DW.add('e', 6, '[moment; force] link j exerts on its environment')
DW_W = DW.add('w', 15, 'its part of fixed direction: n, f, then M (9, '
              'row-major) = p f^T - (p . f) 1 at its point p')
DW_Y = DW.add('y', 6, 'Y_j, what q_j does to the wrench joint j carries')
DW_U = DW.add('u', 3, "U_j, the fixed-direction wrenches' share for j's "
              'row')
DW_T = DW.add('t', 1, "tau_j = S_j . F_j, joint j's component of its wrench")
DW_ACC = DW.add('acc', 21, 'F and W the children of a branch point carried '
                'back')
DW_WIDTH = DW.width
DS = Columns('DS_', 'dw scratch row')
DS_F = DS.add('f', 6, 'running composite wrench')
DS_W = DS.add('w', 15, 'composite fixed-direction data')

# every declaration, for the tests and the documentation
DECLARATIONS = (LINKS, FRAMES, TREE, CONST, WS, AW, CW, CS, DW, DS)

# ---- switches and status codes -------------------------------------------
# Wrench modes: where the end-effector wrench's axes are.
WRENCH_NONE = 0
WRENCH_BASE = 1
WRENCH_EE = 2

# Bits of an entry point's ``flags``.
GRAVITY = 1
VELOCITY = 2
WRENCH_SHIFT = 2     # the wrench mode, shifted (two bits)
WRENCH_BITS = 3      # mask of the mode once shifted
LINK_WRENCHES = 16   # wrenches at links (``fext``) are applied

# Status codes returned by the kernels (-1 is success):
#   1000 * a + i   input a (0 q, 1 qd, 2 qdd or tau, 3 wrench) is not
#                  finite at index i
NONFINITE = 1000
SIZE = 8000      # + a: input a has the wrong size (4: an output, 5: the
#                  workspace)
OVERFLOW = 9000  # finite inputs overflowed in the result
SINGULAR = 10000  # + j: no inertia moves with joint j (D is singular)
MIMIC = 20000    # the articulated-body algorithm met a mimic joint: the
#                  caller solves D qdd = tau - bias instead


def flags(gravity=True, velocity=True, wrench_mode=WRENCH_NONE,
          link_wrenches=False):
    """Return the ``flags`` integer of the entry points."""
    return ((GRAVITY if gravity else 0) | (VELOCITY if velocity else 0)
            | (wrench_mode << WRENCH_SHIFT)
            | (LINK_WRENCHES if link_wrenches else 0))


def pack(links, frames):
    """Stack the link rows and the fixed-frame rows into one array."""
    import numpy as np
    n = len(links)
    packed = np.zeros((n + F_ROWS, L_WIDTH), dtype=np.asarray(links).dtype
                      if n else np.float64)
    if n:
        packed[:n] = links
    packed[n:, :12] = frames
    return packed
