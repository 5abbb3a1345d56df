"""Serial chains: pure, batched algorithms on :class:`~kinestat.mechanism.chain.ChainModel`.

- :mod:`.fk` — forward kinematics (the theses' forward analysis), link frames, joint axes.
- :mod:`.jacobian` — the space Jacobian (Nadkarni eq. 4-11).
- :mod:`.ik` — numerical inverse kinematics (Levenberg–Marquardt; the reverse analysis).
- :mod:`.puma762` — the PUMA 762 in closed form (a package: params, forward, reverse, selection).
- :mod:`.guidance` — Nadkarni's resolved-rate guidance (DISP).
- :mod:`.lengths` — the one characteristic length; :mod:`.chunks` — the one chunk helper.

Public functions always run compiled kernels (``_kernels``, ``_ik_kernels``,
``puma762._kernels``); their NumPy references live in ``_reference`` modules for the tests, and
the kernels' per-model arrays in ``_kernel_cache`` (outside the immutable model).
"""
