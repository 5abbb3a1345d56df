"""Studies at scale: workspace, platform working range, platform design, tolerance (issue 18).

Layer 3 (beside :mod:`kinestat.viz` and :mod:`kinestat.disp`): a study is a pure, chunked
description built from a JSON spec (:mod:`~kinestat.studies.base`); the kernels it calls
(:func:`kinestat.fk`, :func:`kinestat.jacobian`, :mod:`kinestat.parallel`) know nothing of how
it is run. :mod:`~kinestat.studies.engine` runs the chunks on Dask, writes per-chunk results
atomically (:mod:`~kinestat.studies.store`), resumes after an interruption and reduces the
partial summaries in chunk order (:mod:`~kinestat.studies.reduce`), so a summary is the same
bit for bit on any cluster. See docs/sweeps.md.

- :mod:`~kinestat.studies.workspace` — reach and dexterity of an arm over joint grids/samples.
- :mod:`~kinestat.studies.platform_range` — the platform over its working range (Vibhute 2011
  Table 3-1): leg deflections and forces, stiffness, singularity.
- :mod:`~kinestat.studies.platform_design` — special 6-6 designs scored on Table 3-1.
- :mod:`~kinestat.studies.tolerance` — Monte-Carlo of mounting and calibration errors → wrench
  error of the platform used as a force/torque sensor.
"""

from __future__ import annotations

from kinestat.studies.base import STUDIES, Study, build_study, spec_hash

__all__ = ["STUDIES", "Study", "build_study", "spec_hash"]
