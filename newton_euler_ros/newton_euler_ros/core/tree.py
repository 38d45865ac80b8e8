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
A model's tree: parents, mimic joints, and the kernel arrays built on them.

Bodies.  A model has nb moving joints, each with the rigid body it moves
(its child link and everything fixed to it), numbered so that a parent
comes before its children (Featherstone's and Pinocchio's convention):
``parents[j] < j``, -1 for a joint on the base.  A chain is the tree with
``parents[j] = j - 1``.

Mimic joints.  ``mimic[j]`` is None for an independent joint, or
``(leader, multiplier, offset)``: joint j then moves by q_j = multiplier
q_leader + offset (the URDF's ``<mimic>``), the leader an independent
body.  Only the independent joints are coordinates: n of them, numbered
in body order (``coordinates``).  The follower's inertia, motion and
torque act through its leader: tau = G^T tau_b, D = G^T D_b G, J = J_b G,
with G the nb x n matrix whose row j holds the multiplier in the
leader's column.

:func:`check_tree` validates both; :func:`compile_arrays` builds the
kernels' arrays (``kernels.layout``) in any number type.
"""
from . import kernels as K
from .transforms import (_apply, _compose, _identity, _mul, _transpose,
                         axis_frame, evaluate_ops, Float64Math, matrix_op)

REVOLUTE = 'revolute'


def chain_parents(nb):
    """Return the parents of a chain of nb bodies: (-1, 0, 1, ...)."""
    return tuple(range(-1, nb - 1))


def check_tree(names, parents, mimic):
    """
    Validate parents and mimic joints of bodies ``names``; raise ValueError.

    Returns (parents, mimic) as tuples of ints and of None or
    (int, float, float).
    """
    nb = len(names)
    parents = tuple(int(p) for p in parents)
    if len(parents) != nb:
        raise ValueError(f'parents must have {nb} entries (one per moving '
                         f'joint), got {len(parents)}')
    for j, p in enumerate(parents):
        if not -1 <= p < j:
            raise ValueError(
                f'joint {names[j]!r}: parent index {p} must be -1 (the base) '
                f'or a body before it (0..{j - 1}): parents come first')
    mimic = tuple(mimic) if mimic is not None else (None,) * nb
    if len(mimic) != nb:
        raise ValueError(f'mimic must have {nb} entries, got {len(mimic)}')
    out = []
    for j, m in enumerate(mimic):
        if m is None:
            out.append(None)
            continue
        leader, mult, offset = m
        leader = int(leader)
        if not 0 <= leader < nb or leader == j:
            raise ValueError(f'joint {names[j]!r}: mimic leader index '
                             f'{leader} is not another moving joint')
        if mimic[leader] is not None:
            raise ValueError(
                f'joint {names[j]!r}: its mimic leader {names[leader]!r} '
                f'follows another joint itself (give the root leader)')
        out.append((leader, float(mult), float(offset)))
    return parents, tuple(out)


def children(parents):
    """Return each body's children, as lists of body indices."""
    kids = [[] for _ in parents]
    for j, p in enumerate(parents):
        if p >= 0:
            kids[p].append(j)
    return kids


def branch_points(parents):
    """Return, per body, whether a child of it is not the next body."""
    return [any(c != j + 1 for c in kids)
            for j, kids in enumerate(children(parents))]


def coordinates(mimic):
    """
    Return (independent, coordinate of each body).

    ``independent`` lists the bodies that are coordinates, in body order;
    a follower's coordinate is its leader's.
    """
    independent = [j for j, m in enumerate(mimic) if m is None]
    index = {j: k for k, j in enumerate(independent)}
    coord = [index[j] if m is None else index[m[0]]
             for j, m in enumerate(mimic)]
    return tuple(independent), coord


def support(parents, j):
    """Return body j and its ancestors, from j down to the root body."""
    out = []
    while j >= 0:
        out.append(j)
        j = parents[j]
    return out


def compile_arrays(model, m=Float64Math):
    """
    Compile a model into its kernel arrays, in the number type of ``m``.

    Returns ``(links, frames)`` as nested lists (``links``: nb rows of
    ``K.L_WIDTH``, filled by the field names of ``K.LINKS``, the one
    declaration of its columns; ``frames``: ``K.F_ROWS`` rows of 12).  See
    ``model``'s docstring for the kernel frames: row j holds joint j's
    placement P_j = B_lambda(j) Pre_j A_j (B_k = A_k^T Post_k, the pose of
    link frame k in kernel frame k, identity for the base), the link's
    mass, centre of mass and inertia re-expressed in kernel frame j, B_j
    itself (for poses of the link frames), the parent, the coordinate
    that moves the joint (with its multiplier and offset) and whether a
    child of it is not the next body.
    """
    nb = model.nb
    z = m.num(0.0)
    parents = model.parents
    _, coord = coordinates(model.mimic)
    store = branch_points(parents)
    B = []
    links = []
    for j in range(nb):
        A = axis_frame(model.joint_axis[j], m)
        pre = evaluate_ops(model.joint_pre[j], m)
        B_prev = B[parents[j]] if parents[j] >= 0 else _identity(m)
        P = _compose(_compose(B_prev, pre), (A, [z, z, z]))
        Bj = _compose((_transpose(A), [z, z, z]),
                      evaluate_ops(model.joint_post[j], m))
        B.append(Bj)
        RB, pB = Bj
        c = [m.num(v) for v in model.com[j]]
        t = _apply(RB, c)
        com = [t[i] + pB[i] for i in range(3)]
        inertia = [[m.num(v) for v in row] for row in model.inertia[j]]
        inertia = _mul(_mul(RB, inertia), _transpose(RB))
        mim = model.mimic[j]
        row = K.LINKS.row(
            z,
            type=m.num(0.0 if model.joint_types[j] == REVOLUTE else 1.0),
            r=[x for r in P[0] for x in r],
            p=P[1],
            mass=m.num(model.mass[j]),
            com=com,
            inertia=[x for r in inertia for x in r],
            body=[x for r in RB for x in r] + list(pB),
            parent=m.num(float(parents[j])),
            lead=m.num(float(coord[j])),
            mult=m.num(1.0 if mim is None else mim[1]),
            offset=m.num(0.0 if mim is None else mim[2]),
            store=m.num(1.0 if store[j] else 0.0))
        links.append(row)
    tool_body = -1 if model.tool_body is None else model.tool_body
    on = B[tool_body] if tool_body >= 0 else _identity(m)
    tool = _compose(on, evaluate_ops([matrix_op(model.tool)], m))
    base = evaluate_ops([matrix_op(model.base)], m)
    frames = [[z] * 12 for _ in range(K.F_ROWS)]
    frames[K.F_CONST][:len(K.CONSTANTS)] = [m.num(c) for c in K.CONSTANTS]
    for row, (R, p) in ((K.F_BASE, base), (K.F_TOOL, tool)):
        frames[row][:9] = [x for r in R for x in r]
        frames[row][9:] = p
    g = [m.num(v) for v in model.gravity]
    frames[K.F_GRAV][:3] = _apply(_transpose(base[0]), g)
    frames[K.F_TREE][K.T_NQ] = m.num(float(model.n))
    frames[K.F_TREE][K.T_TOOL] = m.num(float(tool_body))
    frames[K.F_TREE][K.T_BRANCHED] = m.num(
        1.0 if any(p != j - 1 for j, p in enumerate(parents)) else 0.0)
    return links, frames
