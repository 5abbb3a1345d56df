"""What the compiled serial kernels share: the Numba options and the constants Numba freezes at
compile time (:mod:`kinestat.serial._kernels`, :mod:`kinestat.serial._ik_kernels`,
:mod:`kinestat.robots.puma762._kernels`)."""

from __future__ import annotations

import math

__all__ = ["OPTS", "INLINE", "PI", "TWO_PI", "SQRT8"]

#: ``cache``: compiled on first use, cached in ``__pycache__``; IEEE arithmetic; numpy errors
OPTS = {"cache": True, "fastmath": False, "nogil": True, "error_model": "numpy"}
#: a helper inlined into its callers (Numba IR level): never compiled on its own, so no disk
#: cache (whose set-up costs each dispatcher ~0.07 ms at import)
INLINE = {**OPTS, "cache": False, "inline": "always"}
PI = math.pi
TWO_PI = 2.0 * math.pi
#: the largest |R_a − R_b| (Frobenius) of two rotations, for the angle 2 asin(d / √8)
SQRT8 = 2.0 * math.sqrt(2.0)
