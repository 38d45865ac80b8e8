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
The kernels' array layouts: every column and row by name.

The kernels take a robot as two arrays, ``links`` (one row per joint) and
``frames`` (fixed frames and constants), and write into workspace arrays
(``ws``, ``aw``, ``cw``) owned by a :class:`~newton_euler_ros.core.Workspace`.
numba wants plain 2-D arrays; these names are how the code addresses them:
a field of width k starts at its column and takes k consecutive ones (a
3x3 matrix is 9 columns row-major, a 6x6 one 36).

Everything here is importable from :mod:`newton_euler_ros.core.kernels`
(``from newton_euler_ros.core.kernels import L_MASS, F_GRAV``).
"""

# ---- ``links``: one row per moving joint (body), in kernel frames -------
# (see ``model.compile_arrays``).  The bodies form a tree numbered so that
# a parent comes before its children: the parent of body j is body
# lambda(j) < j, or the base (-1); a chain has lambda(j) = j - 1.  Kernel
# frame j is kernel frame lambda(j) moved by the constant placement
# (R, p), then by Rz(q_j) (revolute) or Tz(q_j) (prismatic).  The joint
# axis is z of kernel frame j and passes through its origin.  A mimic
# joint has no coordinate of its own: its angle is mult * q[lead] + offset
# (an independent joint: lead its own coordinate, mult 1, offset 0).
L_TYPE = 0       # 0.0 revolute, 1.0 prismatic
L_R = 1          # 9, row-major: placement rotation in kernel frame lambda(j)
L_P = 10         # 3: placement origin in kernel frame lambda(j)
L_MASS = 13
L_COM = 14       # 3 columns, kernel frame j
L_INERTIA = 17   # 9 columns, row-major, about the com in kernel-frame axes
L_BODY = 26      # 12: R (9) then p (3) of link frame j in kernel frame j
L_PARENT = 38    # lambda(j), the parent body (-1.0: the base)
L_LEAD = 39      # the coordinate (index into q) that moves joint j
L_MULT = 40      # its multiplier (1.0 for an independent joint)
L_OFFSET = 41    # its offset (0.0 for an independent joint)
L_STORE = 42     # 1.0 when a child of j is not j + 1: the passes keep
#                  j's state in the workspace for it (a branch point)
L_WIDTH = 43

# ---- ``frames``: rows of fixed frames, shape (F_ROWS, 12) ----------------
F_BASE = 0       # R (9, row-major) then p (3): DH frame 0 in the base frame
F_TOOL = 1       # end-effector frame in the last link frame
F_GRAV = 2       # first 3 entries: gravity in frame-0 axes
F_CONST = 3      # the constants below, in the arrays' own number type
F_TREE = 4       # the tree's shape, the T_* columns below
F_ROWS = 5

# Columns of the tree row ``frames[F_TREE]`` (integers, in the arrays'
# number type).
T_NQ = 0         # the number of coordinates n (independent joints)
T_TOOL = 1       # the body carrying the end-effector frame (-1: the base)
T_BRANCHED = 2   # 1 when some body's parent is not the body before it

# Columns of the constants row ``frames[F_CONST]``.  A float literal in
# numba code is a float64, and float32 op float64 is float64: the kernels
# take every constant from this row so that they compute purely in the
# dtype of the arrays they are given (float64, float32, or mpmath's mpf).
C_ZERO = 0       # 0.0
C_HALF = 1       # 0.5
C_ONE = 2        # 1.0
CONSTANTS = (0.0, 0.5, 1.0)

# ---- ``ws``: the per-joint workspace of every pass (n rows) --------------
W_R = 0          # 9: rotation of kernel frame j in kernel frame j-1
W_P = 9          # 3: origin of kernel frame j in kernel frame j-1
W_F = 12         # 3: net force on link j (m a_c), Newton-Euler
W_N = 15         # 3: net moment about the com, Newton-Euler
W_CT = 18        # cos(q_j) (1 for a prismatic joint)
W_ST = 19        # sin(q_j) (0 for a prismatic joint)
W_DD = 20        # q_j for a prismatic joint (0 for a revolute one)
W_X = 21         # 24: a branch point's state for its children (each pass
#                  its own: velocities, accelerations, poses)
W_ACC = 45       # 12: what a branch point's children carried back to it
#                  (wrenches, composite bodies), summed
W_R0 = 57        # 9: rotation of kernel frame j in the base frame (link
#                  wrenches in base axes)
W_WIDTH = 66

# ---- ``aw``: the articulated-body workspace (n + 1 rows; row n scratch) --
# Spatial vectors are [angular; linear] (motion) or [moment; force]
# (force) at the origin of the frame whose axes they are in.
A_IA = 0         # 36: articulated inertia of link j about O_j, frame j
A_PA = 36        # 6: articulated bias force
A_V = 42         # 6: spatial velocity of link j
A_C = 48         # 6: velocity-product acceleration v_j x (S_j qd_j)
A_U = 54         # 6: U = IA S (the column of IA on the joint axis)
A_D = 60         # d = S^T IA S, the articulated inertia on the axis
A_UU = 61        # u = tau - S^T pA
A_A = 62         # 6: spatial acceleration of a branch point
A_WIDTH = 68

# ---- ``cw``: the composite Coriolis workspace (n + 1 rows) ---------------
# Row n is scratch: the composite inertia IC (36), the composite Coriolis
# matrix BC (36), then I_j V_j (6), at the columns CS_* below.
CW_S = 0         # 6: motion subspace of joint j, frame 0 at its origin
CW_SD = 6        # 6: its rate, V_j x S_j
CW_F1 = 12       # 6: IC_j S_j
CW_F2 = 18       # 6: BC_j^T S_j
CW_G = 24        # 6: IC_j Sdot_j + BC_j S_j
CW_RW = 30       # 9: rotation of kernel frame j in frame 0
CW_OW = 39       # 3: origin of kernel frame j in frame 0
CW_V = 42        # 6: spatial velocity of link j
CW_I = 48        # 36: spatial inertia of link j, frame 0 about its origin
CW_ICA = 84      # 36: composite inertia the children of a branch point
#                  carried back to it (summed)
CW_BCA = 120     # 36: the same of their composite Coriolis matrices
CW_WIDTH = 156
CS_IC = 0        # scratch row: composite inertia (36)
CS_BC = 36       # composite Coriolis matrix (36)
CS_H = 72        # I_j V_j (6)

# ---- ``dw``: the derivative workspace (n + 1 rows) -------------------------
# Spatial vectors in frame 0 about its origin, as in ``cw`` (derivatives.py).
# Row n is scratch: the running composite wrench F (6) and world-fixed
# wrench data W (15) at the columns DS_* below.
DW_A = 0         # 6: spatial acceleration of link j, gravity as the base's
DW_C = 6         # 6: c_j = S_j x A_lambda(j) + Sdot_j x V_lambda(j)
DW_E = 12        # 6: [moment; force] link j exerts on its environment
DW_W = 18        # 15: its part of fixed direction: n, f, then M (9,
#                  row-major) = p f^T - (p . f) 1 at its point p
DW_Y = 33        # 6: Y_j, what q_j does to the wrench joint j carries
DW_U = 39        # 3: U_j, the fixed-direction wrenches' share for j's row
DW_T = 42        # tau_j = S_j . F_j, joint j's component of its wrench
DW_ACC = 43      # 21: F and W the children of a branch point carried back
DW_WIDTH = 64
DS_F = 0         # scratch row: composite wrench (6)
DS_W = 6         # composite fixed-direction data (15)

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
