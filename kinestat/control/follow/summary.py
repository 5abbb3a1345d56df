"""The follow run's report figures from its per-cycle summaries (the JSON keys are a
contract)."""

from __future__ import annotations

import numpy as np

__all__ = ["follow_summary"]


def follow_summary(cycles: list[dict], target_force: float, travel: float) -> dict:
    """The follow report's figures from the loop's per-cycle summaries: ``travel`` (mm, the
    measured path along the surface), the normal-force errors over the travel cycles (from the
    first travel cycle on; measured, and true when simulated), ``contact_lost`` (travel cycles
    without contact), ``auto_tilt`` (whether the automatic tilt was on) and
    ``auto_tilt_from_travel`` (mm travelled when it came on, None if never),
    ``workpiece_compliance_estimate`` (mm/N, the workpiece's give under the normal force
    measured at the settle; 0 when not significant), and once the tip slid with friction
    ``friction_estimate`` (μ̂) and ``friction_force_mean`` (N, the tangential force over those
    cycles)."""
    trav = [c for c in cycles if c.get("phase") == "travel"]
    err = [abs(c["normal_force"] - target_force) for c in trav if c.get("in_contact")]
    out = {"travel": float(cycles[-1]["travel"]) if cycles else 0.0,
           "contact_lost": sum(1 for c in trav if not c.get("in_contact")),
           "normal_force_rms_error": float(np.sqrt(np.mean(np.square(err)))) if err else None,
           "normal_force_max_error": float(max(err)) if err else None}
    on = next((c for c in cycles if c.get("auto_tilt")), None)
    out["auto_tilt"] = on is not None  # the automatic tilt was on (set, or switched itself on)
    out["auto_tilt_from_travel"] = None if on is None else float(on["travel"])
    out["workpiece_compliance_estimate"] = (float(trav[-1].get("workpiece_compliance", 0.0))
                                            if trav else 0.0)
    slid = [c for c in trav if c.get("in_contact") and c.get("friction_ratio")]
    if slid:  # the friction measured, not fought: mu estimate and mean friction force
        out["friction_estimate"] = float(slid[-1]["friction_ratio"])
        out["friction_force_mean"] = float(np.mean([c["tangential_force"] for c in slid]))
    true_err = []
    for c in trav:
        if c.get("true_normal") is not None and c.get("true_force") is not None:
            fn = -float(np.asarray(c["true_force"]) @ np.asarray(c["true_normal"]))
            true_err.append(abs(fn - target_force))
    if true_err:
        out["true_normal_force_rms_error"] = float(np.sqrt(np.mean(np.square(true_err))))
        out["true_normal_force_max_error"] = float(max(true_err))
    return out
