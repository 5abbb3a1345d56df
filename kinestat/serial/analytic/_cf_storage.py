"""Verification and storage of a closed form's candidates (the kernels of
:mod:`kinestat.serial.analytic._cf_kernels` and :mod:`~kinestat.serial.analytic._offset_kernels`):
as angles (:func:`store_angles`, single poses and small batches) or as cosines and sines
(:func:`store_pair`, the parallel batches, whose angles come from one vectorised ``arctan2``
after the kernel: :func:`kinestat.serial.analytic.closed_form.angles_from_pairs`)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from kinestat.serial._numba_options import OPTS as _OPTS
from kinestat.serial.analytic._solution_kernels import polish, pose_errors, scratch, store

#: the count of a pose handed back unsolved: a candidate needs Newton steps the kernel was
#: compiled without (``newton`` None); −1 and −2 are the pose checks' statuses
#: (:func:`kinestat.serial.analytic._cf_kernels._pose_status`)
HANDED_BACK = -3


@nb.njit(**_OPTS)
def store_angles(n, C, Tn, q, f, tol, dedup, newton, out_q, out_valid, out_pos, out_rot, cnt):
    """Verify q (6-tuple) whose forward kinematics f (12 scalars, the chain product at the
    cosines and sines of q) against Tn and store it unless it repeats a stored one; returns the
    new count. A candidate that misses tol (rounding near a singular set) takes ``newton``
    Newton steps; with ``newton`` None (the kernel is then compiled without them: a smaller
    cache to load) the pose is handed back instead: :data:`HANDED_BACK` from then on."""
    if cnt < 0:
        return cnt
    pos, rot = pose_errors(f, Tn)
    if not (pos <= tol and rot <= tol):
        if newton is None:
            return HANDED_BACK
        qa = np.empty(6)
        for i in range(6):
            qa[i] = q[i]
        Ms, Vs = scratch()
        pos, rot = polish(C, Tn, qa, newton, Ms, Vs)
        if not (pos <= tol and rot <= tol):
            return cnt
        q = (qa[0], qa[1], qa[2], qa[3], qa[4], qa[5])
    return store(n, q, pos, rot, dedup, out_q, out_valid, out_pos, out_rot, cnt)


@nb.njit(**_OPTS)
def store_pair(n, C, Tn, c, s, f, tol, chord, newton, out_c, out_s, out_valid, out_pos,
                out_rot, cnt):
    """:func:`store_angles` for the batch kernels, which leave the angles to one vectorised
    ``arctan2`` after the kernel
    (:func:`kinestat.serial.analytic.closed_form.angles_from_pairs`): the candidate is given by its
    cosines c and sines s (6-tuples), stored into ``out_c``, ``out_s``, and it repeats a
    stored one when every joint's (cos, sin) lies within ``chord`` (``2 sin(dedup/2)``: the
    chord of the angle ``dedup``). Newton steps (``newton``, never None here) on a candidate
    that misses tol start from its angles."""
    if cnt < 0:
        return cnt
    pos, rot = pose_errors(f, Tn)
    if not (pos <= tol and rot <= tol):
        qa = np.empty(6)
        for i in range(6):
            qa[i] = math.atan2(s[i], c[i])
        Ms, Vs = scratch()
        pos, rot = polish(C, Tn, qa, newton, Ms, Vs)
        if not (pos <= tol and rot <= tol):
            return cnt
        c = (math.cos(qa[0]), math.cos(qa[1]), math.cos(qa[2]), math.cos(qa[3]),
             math.cos(qa[4]), math.cos(qa[5]))
        s = (math.sin(qa[0]), math.sin(qa[1]), math.sin(qa[2]), math.sin(qa[3]),
             math.sin(qa[4]), math.sin(qa[5]))
    c2 = chord * chord
    for j in range(cnt):
        same = True
        for i in range(6):
            if (c[i] - out_c[n, j, i]) ** 2 + (s[i] - out_s[n, j, i]) ** 2 >= c2:
                same = False
                break
        if same:
            return cnt
    if cnt >= out_c.shape[1]:
        return cnt
    for i in range(6):
        out_c[n, cnt, i] = c[i]
        out_s[n, cnt, i] = s[i]
    out_valid[n, cnt] = True
    out_pos[n, cnt] = pos
    out_rot[n, cnt] = rot
    return cnt + 1
