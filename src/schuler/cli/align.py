"""``schuler align``: physical gyrocompassing of a platform INS (source 003).

Commands: ``run`` (one case: accuracy, time, constraint check; ``--monte-carlo N``),
``sweep PARAM=start:stop:step ...`` (the lab's variations), ``reproduce`` (the
design example and the source's errata).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import click
import numpy as np

from schuler.cli.common import emit, json_option, options_named, out_option, parameter_options, parse_options
from schuler.exceptions import InvalidParameter
from schuler.gyrocompassing import api
from schuler.results import Result
from schuler.units import to_unit

_BY_NAME = {p.name: p for p in api.PARAMETERS}
_SWEEPABLE = [name for name in api.CASE_FIELDS if name != "max_latitude"]
_SHORT_HEADERS = {
    "azimuth_error_arcmin": "delta sim [arcmin]",
    "azimuth_error_analytic_arcmin": "delta (1.21) [arcmin]",
    "level_error_beta_arcmin": "beta [arcmin]",
    "settling_time_s": "t 5/h [s]",
    "settling_time_simulated_s": "t 1 % [s]",
    "constraints_ok": "constraints",
}


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
def group():
    """Physical gyrocompassing (azimuth alignment) of a semi-analytic platform INS.

    Defaults: latitude 50 deg, T = 30 s, zeta = 0.8 (c_a = 1/(T^2 U cos(latitude)),
    c_Gamma = 2 zeta/T), initial azimuth error 1 deg, levelled platform, no error sources.
    """


def _run_files(result: api.AlignmentResult, out_dir) -> list:
    from schuler.gyrocompassing import plots
    from schuler.io import write_dataframe_csv
    import pandas as pd

    run = result.run
    runs = {f"{result.model} model": run}
    if result.model != "simplified":
        runs["simplified model (1.19)"] = result.simplified_run
    figures = {
        "align_time_history": plots.time_history(runs),
        "align_phase_trajectory": plots.phase_trajectory(runs),
    }
    if result.monte_carlo is not None:
        mc = result.monte_carlo
        figures["align_monte_carlo"] = plots.monte_carlo_histogram(
            mc.samples_arcmin, mc.azimuth_error_sigma_analytic_arcmin, mc.azimuth_error_mean_arcmin, result.model)
    files = plots.write_figures(figures, out_dir)
    columns = {"time_s": run.time, "delta_rad": run.delta, "beta_rad": run.beta, "delta_rate_rad_per_s": run.delta_rate}
    if run.alpha is not None:
        columns.update({"alpha_rad": run.alpha, "mu_rad": run.mu, "nu_rad": run.nu})
    files.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "align_time_history.csv"))
    return files


@group.command("run")
@parameter_options(api.PARAMETERS)
@out_option
@json_option
def run_command(out_dir, as_json, **options):
    """One gyrocompassing case: accuracy (arcmin), settling time and the constraint check."""
    values = parse_options(api.PARAMETERS, options)
    with options_named(api.PARAMETERS):
        result = api.run(**values)
    files = _run_files(result, out_dir) if out_dir else []
    emit(result, as_json, inputs=values, files=files)


@dataclass
class SweepResult(Result):
    """A grid of gyrocompassing cases: one column per result (display units in the names)."""

    model: str
    swept: list
    simulated: bool
    columns: dict
    all_constraints_ok: bool | None = None
    notes: list = field(default_factory=list)

    units = {"c_gamma": "1/s", "c_a": "1/s"}

    def render(self):
        from rich.table import Table

        table = Table(title=f"Gyrocompassing sweep, {self.model} model (all columns in --json)")
        names = [name for name in self.columns if name in _SHORT_HEADERS or name.startswith(tuple(self.swept))]
        for name in names:
            table.add_column(_SHORT_HEADERS.get(name, name), justify="right")
        for i in range(len(self.columns[names[0]])):
            table.add_row(*(_cell(self.columns[name][i]) for name in names))
        return table


def _cell(value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, (bool, np.bool_)):
        return "ok" if value else "VIOLATED"
    value = float(value)
    return "not settled" if math.isinf(value) else f"{value:.5g}"


def _parse_axis(spec: str) -> tuple[str, np.ndarray]:
    """``name=start:stop:step`` (stop included when on the grid) or ``name=v1,v2,...``.

    Numbers are in the parameter's display unit unless a unit follows them
    (``drift_east=1:5:1 mdeg/h``). Returns the name and the SI values.
    """
    name, sep, text = spec.partition("=")
    name = name.strip().replace("-", "_")
    if not sep or not text:
        raise InvalidParameter("sweep", f"{spec!r}: expected PARAM=start:stop:step or PARAM=v1,v2,...")
    if name == "model":
        return name, np.array([_BY_NAME[name].parse(choice, "model") for choice in text.split(",")])
    if name not in _SWEEPABLE:
        raise InvalidParameter(name, f"cannot be swept; choose from {', '.join(_SWEEPABLE + ['model'])}")
    parameter = _BY_NAME[name]
    numbers, _, unit = text.strip().partition(" ")  # an optional unit after the numbers: "0:0.05:0.01 deg/h"
    try:
        parts = [float(p) for p in numbers.split(":")] if ":" in numbers else None
        listed = None if parts else [float(p) for p in numbers.split(",")]
    except ValueError:
        raise InvalidParameter(name, f"{text!r}: numbers in {parameter.unit or 'plain units'} expected")
    if parts is not None:
        if len(parts) != 3:
            raise InvalidParameter(name, f"{text!r}: expected start:stop:step")
        start, stop, step = parts
        if step == 0 or (stop - start) * step < 0 or not all(map(math.isfinite, parts)):
            raise InvalidParameter(name, f"{text!r}: the step must be finite and lead from start to stop")
        count = int(math.floor((stop - start) / step + 1e-9)) + 1
        if count > 100_000:
            raise InvalidParameter(name, f"{text!r}: {count} values; at most 100000 per axis")
        listed = (start + step * np.arange(count)).tolist()
    unit = unit.strip()
    return name, np.array([parameter.parse(f"{value!r} {unit}" if unit else value, parameter.option) for value in listed])


def _shown(name: str, value) -> str:
    """A swept value in its display unit, for labels."""
    unit = _BY_NAME[name].unit
    return _cell(to_unit(value, unit) if unit and name != "model" else value)


@group.command("sweep")
@click.argument("axes", nargs=-1, required=True, metavar="PARAM=start:stop:step ...")
@parameter_options([p for p in api.PARAMETERS if p.name not in ("monte_carlo", "sigma_drift", "sigma_drift_z",
                                                                 "sigma_accel", "seed")])
@click.option("--analytic", "analytic_only", is_flag=True, help="Closed forms only (no simulation, no constraint check).")
@out_option
@json_option
def sweep_command(axes, analytic_only, out_dir, as_json, **options):
    """Vary parameters over a grid (lab task 1): accuracy, time and constraints per case.

    Each PARAM=start:stop:step (or PARAM=v1,v2,...) is in the option's display
    unit, e.g. latitude=0:80:10 (deg), drift_east=0:0.05:0.01 (deg/h), or in
    the unit written after them ("latitude_error=0:2:0.5 deg"); stop is
    included when it falls on the grid. Several PARAMs make a grid; the other
    options fix the remaining parameters. model=full,simplified compares the
    models case by case (lab tasks 2 and 3).
    """
    parameters = [p for p in api.PARAMETERS if p.name in options]
    fixed = parse_options(parameters, options)
    grid_axes = dict(_parse_axis(spec) for spec in axes)
    from schuler.gyrocompassing.study import sweep_grid

    grid = sweep_grid(grid_axes)
    n = len(next(iter(grid.values())))
    values = {k: v for k, v in fixed.items() if v is not None and k not in grid} | grid
    out = api.sweep(values, simulate_runs=not analytic_only)
    columns = {}
    keys = {}
    for name in grid:
        unit = _BY_NAME[name].unit if name != "model" else ""
        keys[name] = f"{name}_{unit.replace('/', '_per_')}" if unit else name
        columns[keys[name]] = to_unit(grid[name], unit) if unit else grid[name]
    columns["azimuth_error_analytic_arcmin"] = to_unit(out["azimuth_error_analytic_rad"], "arcmin")
    columns["azimuth_error_closed_form_arcmin"] = to_unit(out["azimuth_error_rad"], "arcmin")
    if not analytic_only:
        columns["azimuth_error_arcmin"] = to_unit(out["azimuth_error_simulated_rad"], "arcmin")
    columns["level_error_beta_arcmin"] = to_unit(
        out["level_error_beta_rad" if analytic_only else "level_error_beta_simulated_rad"], "arcmin")
    columns["settling_time_s"] = out["settling_time_s"]
    if not analytic_only:
        columns["settling_time_simulated_s"] = out["settling_time_simulated_s"]
        columns["constraints_ok"] = out["constraints_ok"]
    columns["c_gamma"] = out["c_gamma"]
    columns["c_a"] = out["c_a"]
    result = SweepResult(
        model="by case" if "model" in grid else str(fixed["model"]), swept=list(grid), simulated=not analytic_only,
        columns={k: np.asarray(v) for k, v in columns.items()},
        all_constraints_ok=None if analytic_only else bool(np.all(out["constraints_ok"])),
        notes=[f"{n} cases"],
    )
    files = []
    if out_dir:
        from schuler.gyrocompassing import plots
        from schuler.io import write_dataframe_csv
        import pandas as pd

        first = next((name for name in grid if name != "model"), "model")
        x_name = keys[first]
        others = [name for name in grid if name != first]
        groups = None
        if others:
            groups = np.array([", ".join(f"{o}={_shown(o, grid[o][i])}" for o in others) for i in range(n)])
        unit = _BY_NAME[first].unit
        figure = plots.sweep_curves(columns[x_name], f"{first} [{unit}]" if unit else first, columns, groups)
        files = plots.write_figures({"align_sweep": figure}, out_dir)
        files.append(write_dataframe_csv(pd.DataFrame(columns), out_dir / "align_sweep.csv"))
    emit(result, as_json, inputs=values, files=files)


@group.command("reproduce")
@json_option
def reproduce_command(as_json):
    """The source's design example (T = 30 s) and its errata, printed beside the computed values."""
    emit(api.reproduce(), as_json)
