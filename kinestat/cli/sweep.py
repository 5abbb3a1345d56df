"""``kinestat sweep``: studies at scale on Dask — workspace, platform range, design, tolerance.

Every study takes ``--output DIR`` (default ``./kinestat-runs/<study>-<spec hash>``, so the same
command resumes an interrupted run), ``--scheduler tcp://HOST:PORT`` (default: an embedded local
cluster, one worker process per core), ``--json``, and ``--samples N --seed S`` (random inputs) or
``--grid N`` (N values per axis over its range, both ends, full tensor grid). Output: summary.json
(only once complete), per-chunk partial summaries under chunks/, Parquet rows under rows/, PNG
plots under plots/. See
docs/sweeps.md.
"""

from __future__ import annotations

import functools
import inspect
import math
import os
import warnings
from collections.abc import Callable

import typer

from kinestat.cli._model import (
    MODEL_HELP,
    base_option,
    length_unit_option,
    load_model,
    scale_option,
    tip_option,
)
from kinestat.cli._options import XYZ_METAVAR, check_output_dir, flag, name_value, path_value
from kinestat.cli._output import console, parse_floats, print_json, table
from kinestat.errors import InputError, KinestatWarning

sweep_app = typer.Typer(
    name="sweep",
    help="Studies at scale on Dask: workspace, platform-range, platform-design, tolerance.",
    no_args_is_help=True,
)

OUTPUT = typer.Option(None, "--output", parser=path_value, help="Output directory (default "
                      "./kinestat-runs/<study>-<spec hash>; an existing one resumes).",
                      metavar="DIR")
SCHEDULER = typer.Option(None, "--scheduler", help="Dask scheduler address tcp://HOST:PORT "
                         "(default: an embedded local cluster).", metavar="tcp://HOST:PORT")
WORKERS = typer.Option(None, "--workers",
                       help="Local cluster: worker count (default: cores; at most 4 per core).")
THREADS = flag(False, "--threads", help="Local cluster: thread workers, not processes.")
TIMEOUT = typer.Option(10.0, "--timeout", help="Seconds to wait for the scheduler and a worker.")
SEED = typer.Option(0, "--seed", help="Seed of the random inputs (--samples).")
CHUNK = typer.Option(None, "--chunk-size", help="Evaluations per chunk (default per study).")
MAX_CHUNKS = typer.Option(None, "--max-chunks", help="Stop after computing this many new chunks "
                          "(a staged run; rerun the command to resume).")
NO_ARRAYS = flag(False, "--no-arrays", help="Write only summaries, no per-row Parquet.")
NO_PLOTS = flag(False, "--no-plots", help="Do not write PNG plots.")
QUIET = flag(False, "--quiet", help="No progress bar.")
JSON = flag(False, "--json", help='JSON: {"study", "summary", "output", "chunks", '
                    '"elapsed_s", "complete", "plots"}.')
PLATFORM = typer.Option(None, "--platform", parser=name_value,
                        help="TOML platform file (default: the embedded "
                        "2011 prototype).", metavar="FILE")
RANGE_MM = typer.Option("3.5,3.5,4", "--range-mm", help="Motion range +- x,y,z (length unit; "
                        "Vibhute Table 3-1).", metavar=XYZ_METAVAR)
RANGE_DEG = typer.Option("4,4,6", "--range-deg", help="Motion range +- about x,y,z (degrees).",
                         metavar=XYZ_METAVAR)
MAX_DEFL = typer.Option(5.0, "--max-deflection", help="Connector deflection limit (Table 3-1).")
MAX_LOAD = typer.Option(50.0, "--max-load", help="Perpendicular load limit |F_z| (Table 3-1).")

_BULKY = ("histograms", "slices", "stiffness_home")


def register(app: typer.Typer) -> None:
    app.add_typer(sweep_app, name="sweep")


#: the options every study command takes after its own, with their types (Typer has no shared
#: option groups: :func:`_study_command` adds them to each command's signature)
_COMMON = (("chunk_size", int, CHUNK), ("output", str, OUTPUT), ("scheduler", str, SCHEDULER),
           ("workers", int, WORKERS), ("threads", bool, THREADS), ("timeout", float, TIMEOUT),
           ("max_chunks", int, MAX_CHUNKS), ("no_arrays", bool, NO_ARRAYS),
           ("no_plots", bool, NO_PLOTS), ("quiet", bool, QUIET), ("as_json", bool, JSON))
#: the common options that say how to run the study (the others shape its spec)
_RUN_OPTIONS = ("output", "scheduler", "workers", "threads", "timeout", "max_chunks",
                "no_plots", "quiet", "as_json")


def _study_command(name: str):
    """Register ``build`` as ``kinestat sweep NAME``: ``build`` takes the command's own options
    plus ``chunk_size`` (None: the study's default) and ``arrays``, and returns the study's
    spec; the command also takes the common options (:data:`_COMMON`) and runs the spec."""

    def register_build(build: Callable[..., dict]):
        own = [p for p in inspect.signature(build, eval_str=True).parameters.values()
               if p.name not in ("chunk_size", "arrays")]
        common = [inspect.Parameter(n, inspect.Parameter.KEYWORD_ONLY, default=d, annotation=t)
                  for n, t, d in _COMMON]

        @functools.wraps(build)
        def command(**options) -> None:
            _check_run_options(options)
            run = {k: options.pop(k) for k in _RUN_OPTIONS}
            arrays = not options.pop("no_arrays")
            _run(name, build(**options, arrays=arrays), **run)

        command.__signature__ = inspect.Signature([*own, *common], return_annotation=None)
        command.__annotations__ = {p.name: p.annotation for p in (*own, *common)}
        return sweep_app.command(name)(command)

    return register_build


def _check_run_options(options: dict) -> None:
    """``--chunk-size`` (≥ 1 when given: 0 is not "the default") and ``--timeout`` (a finite
    number of seconds > 0), before anything is built or started."""
    chunk = options.get("chunk_size")
    if chunk is not None and chunk < 1:
        raise InputError(f"--chunk-size must be at least 1, got {chunk}")
    t = options.get("timeout")
    if not (isinstance(t, (int, float)) and math.isfinite(t) and t > 0):
        raise InputError(f"--timeout must be a finite number of seconds > 0, got {t}")
    workers, cores = options.get("workers"), os.cpu_count() or 1
    if options.get("scheduler") is not None and (workers is not None or options.get("threads")):
        raise InputError("--workers and --threads set up the local cluster; with --scheduler "
                         "the scheduler's own workers run the study")
    if workers is not None and workers > 4 * cores:  # (below 1: the cluster's own check)
        # each worker is a process; beyond a few per core they only queue for the same cores
        # (--workers 100000 tried to start them all)
        raise InputError(f"--workers must be at most {4 * cores} (4 per core on this "
                         f"machine's {cores}), got {workers}")
    check_output_dir(options.get("output"), "--output")


def _chunk(chunk_size: int | None, default: int) -> int:
    return default if chunk_size is None else chunk_size


def _ranges(range_mm: str, range_deg: str) -> dict:
    """``--range-mm`` and ``--range-deg`` as the spec builders' ``range_mm``/``range_deg``."""
    out = {"range_mm": parse_floats(range_mm, 3, "range-mm"),
           "range_deg": parse_floats(range_deg, 3, "range-deg")}
    for key, vals in out.items():
        if (vals < 0).any():
            raise InputError(f"--{key.replace('_', '-')}: half-widths of the motion range must "
                             f"be >= 0, got {', '.join(f'{v:g}' for v in vals)}")
    return out


def _run(study_name: str, spec: dict, *, output, scheduler, workers, threads, timeout,
         max_chunks, no_plots, quiet, as_json) -> None:
    from kinestat.studies.base import build_study  # lazy: start-up (the studies load Dask)
    from kinestat.studies.engine import (  # lazy: start-up (the studies load Dask)
        StudyInterrupted,
        run_study,
    )

    study = build_study(study_name, spec)
    try:
        res = run_study(study, output, scheduler=scheduler, workers=workers,
                        processes=not threads, max_chunks=max_chunks, progress=not quiet,
                        timeout_s=timeout, plots=not no_plots)
    except StudyInterrupted as exc:  # Typer would turn it into a silent exit 130
        typer.echo(f"kinestat: interrupted: {exc.message}", err=True)
        raise typer.Exit(130) from None
    if res.chunks_damaged:
        typer.echo(f"kinestat: warning: {res.chunks_damaged} chunk(s) in {res.output} did not "
                   "match their checksums (manifest.sha256): damaged or unfinished, "
                   "recomputed", err=True)
    out = res.to_json()
    if as_json:
        if out["summary"] is not None:
            out["summary"] = {k: v for k, v in out["summary"].items()
                              if k not in ("histograms", "slices")}
        print_json(out)
        return
    if not res.complete:
        console.print(f"[yellow]incomplete[/]: {res.chunks_reused + res.chunks_computed} of "
                      f"{res.chunks_total} chunks in {res.output}; run the command again to "
                      "resume")
        return
    rows = []
    for k, v in res.summary.items():
        if k in _BULKY or v is None:
            continue
        if isinstance(v, dict):
            for kk, vv in v.items():
                if not isinstance(vv, (dict, list)):
                    rows.append([f"{k}.{kk}", vv])
        elif not isinstance(v, list):
            rows.append([k, v])
    console.print(table(f"{study_name}: {res.chunks_total} chunks "
                        f"({res.chunks_computed} computed, {res.chunks_reused} reused) in "
                        f"{res.elapsed_s:.1f} s", ["quantity", "value"], rows, fmt="{:.6g}"))
    console.print(f"output: {res.output} (summary.json, rows/ Parquet, plots/)")


def _samples_default(grid, samples, default):
    return default if grid is None and samples is None else samples


@_study_command("workspace")
def workspace_command(
    model: str = typer.Option("puma762", "--model", parser=name_value, help=MODEL_HELP),
    grid: int = typer.Option(None, "--grid", help="N values per joint over its limits."),
    samples: int = typer.Option(None, "--samples", help="Random configurations (default "
                                "100000 if no --grid)."),
    seed: int = SEED,
    task: str = typer.Option("auto", "--task", help="Jacobian rows for manipulability/"
                             "condition: auto, full, position, planar."),
    tip: str | None = tip_option(), base: str | None = base_option(),
    scale: float | None = scale_option(), length_unit: str | None = length_unit_option(),
    chunk_size: int | None = None, arrays: bool = True,
) -> dict:
    """Workspace and dexterity of an arm: reach, Yoshikawa manipulability, condition number.

    Summary: points, reach_max, reach_min (distance of the end point from the base origin),
    reach_bound, manipulability {min, mean, max}, condition {min, mean, max}, singular.
    """
    from kinestat.studies.workspace import (  # lazy: start-up (the studies load Dask)
        DEFAULT_CHUNK,
        workspace_spec,
    )

    load_model(model, tip, base, scale, length_unit)  # the loader's warnings, one line each
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", KinestatWarning)
        return workspace_spec(model, grid=grid, samples=_samples_default(grid, samples, 100_000),
                              seed=seed, chunk_size=_chunk(chunk_size, DEFAULT_CHUNK), task=task,
                              arrays=arrays, tip=tip, base=base, scale=scale,
                              length_unit=length_unit)


@_study_command("platform-range")
def platform_range_command(
    platform: str = PLATFORM,
    grid: int = typer.Option(None, "--grid", help="N values per axis over the motion range."),
    samples: int = typer.Option(None, "--samples", help="Random poses (default 20000 if no "
                                "--grid)."),
    seed: int = SEED, range_mm: str = RANGE_MM, range_deg: str = RANGE_DEG,
    max_deflection: float = MAX_DEFL, max_load: float = MAX_LOAD,
    chunk_size: int | None = None, arrays: bool = True,
) -> dict:
    """The platform over its working range: leg deflections/forces, load, stiffness, singularity.

    Summary: poses, within_deflection, within_load, within_both, fraction_within, statistics of
    max_deflection, max_leg_force, force_z, singularity, k_eig_min/max, k_cond; stiffness_home
    (K at home, as `kinestat platform stiffness`); axis_check (Table 3-1 axis by axis).
    """
    from kinestat.studies.platform_range import (  # lazy: start-up (the studies load Dask)
        DEFAULT_CHUNK,
        platform_range_spec,
    )

    return platform_range_spec(
        platform, grid=grid, samples=_samples_default(grid, samples, 20_000), seed=seed,
        max_deflection=max_deflection, max_load=max_load,
        chunk_size=_chunk(chunk_size, DEFAULT_CHUNK), arrays=arrays,
        **_ranges(range_mm, range_deg))


@_study_command("platform-design")
def platform_design_command(
    platform: str = PLATFORM,
    base_side: str = typer.Option(None, "--base-side", help="Base triangle side(s): v, "
                                  "v1,v2,..., lo:hi (with --grid) or lo:hi:n."),
    top_side: str = typer.Option(None, "--top-side", help="Top triangle side(s)."),
    base_offset: str = typer.Option(None, "--base-offset", help="Base edge offset(s)."),
    top_offset: str = typer.Option(None, "--top-offset", help="Top edge offset(s)."),
    height: str = typer.Option(None, "--height", help="Home height(s)."),
    twist_deg: str = typer.Option(None, "--twist-deg", help="Home twist(s), degrees."),
    stiffness: str = typer.Option(None, "--stiffness", help="Spring constant(s)."),
    grid: int = typer.Option(None, "--grid", help="Values taken from each lo:hi range."),
    samples: int = typer.Option(None, "--samples", help="Random designs within each "
                                "parameter's smallest and largest value instead of the grid."),
    seed: int = SEED,
    poses: int = typer.Option(256, "--poses", help="Random poses in the range per design."),
    score: str = typer.Option("table-3-1", "--score", help="What 'best' maximises: "
                              "'table-3-1' (fraction of the motion range within spec) or "
                              "'lee' (|det j| at home over the top side cubed, Lee's "
                              "criterion)."),
    range_mm: str = RANGE_MM, range_deg: str = RANGE_DEG,
    max_deflection: float = MAX_DEFL, max_load: float = MAX_LOAD,
    chunk_size: int | None = None, arrays: bool = True,
) -> dict:
    """Special 6-6 designs scored on Vibhute Table 3-1 or by Lee's criterion (unswept
    parameters: the --platform's).

    Summary: score, designs, valid, meets_spec, fraction_within {min, mean, max},
    min_singularity, lee {min, mean, max}, best (the highest score), reference (the
    --platform's own design, if in the grid).
    """
    from kinestat.studies.platform_design import (  # lazy: start-up (the studies load Dask)
        DEFAULT_CHUNK,
        platform_design_spec,
    )

    given = {"base_side": base_side, "top_side": top_side, "base_offset": base_offset,
             "top_offset": top_offset, "height": height, "twist_deg": twist_deg,
             "stiffness": stiffness}
    return platform_design_spec(
        platform, values={k: v for k, v in given.items() if v is not None}, grid=grid,
        samples=samples, seed=seed, poses=poses, max_deflection=max_deflection,
        max_load=max_load, chunk_size=_chunk(chunk_size, DEFAULT_CHUNK), arrays=arrays,
        score=score,
        **_ranges(range_mm, range_deg))


@_study_command("tolerance")
def tolerance_command(
    platform: str = PLATFORM,
    samples: int = typer.Option(10_000, "--samples", help="Monte-Carlo samples."),
    seed: int = SEED,
    sigma_mount: float = typer.Option(0.05, "--sigma-mount", help="Mounting error of every "
                                      "attachment point, per coordinate (length unit, 1 sigma)."),
    sigma_k: float = typer.Option(0.05, "--sigma-k", help="Relative spring constant error."),
    sigma_offset: float = typer.Option(0.01, "--sigma-offset", help="Encoder zero error per "
                                       "leg (length unit)."),
    range_mm: str = RANGE_MM, range_deg: str = RANGE_DEG,
    chunk_size: int | None = None, arrays: bool = True,
) -> dict:
    """Monte-Carlo of mounting and calibration errors -> error of the measured wrench.

    Summary: samples, failed, force_error and torque_error {mean, rms, max} (torque about the
    top's centre at home), component_rms.
    """
    from kinestat.studies.tolerance import (  # lazy: start-up (the studies load Dask)
        DEFAULT_CHUNK,
        tolerance_spec,
    )

    return tolerance_spec(platform, samples=samples, seed=seed, sigma_mount=sigma_mount,
                          sigma_k=sigma_k, sigma_offset=sigma_offset,
                          chunk_size=_chunk(chunk_size, DEFAULT_CHUNK), arrays=arrays,
                          **_ranges(range_mm, range_deg))
