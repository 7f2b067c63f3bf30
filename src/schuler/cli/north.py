"""``schuler north``: ground gyrocompass during natural rotor run-down (source 004).

Commands: ``simulate`` (write an observation record), ``identify RECORD.csv``
(north from a record), ``reproduce`` (the source's experiment) and ``run``
(simulate and identify in one go).
"""

from __future__ import annotations

from pathlib import Path

import click

from schuler.cli.common import emit, json_option, options_named, out_option, parameter_options, parse_options
from schuler.ground_gyrocompass import api, motion
from schuler.ground_gyrocompass.observations import read_record, write_record


@click.group(name="north")
def group():
    """Ground gyrocompass during natural rotor run-down: north from the azimuth motion.

    The rotor is spun up by a pulse and runs down (H = Hm exp(-lambda t)); the
    sensitive element's azimuth motion is a Bessel-function solution (source 004,
    eq. (9)). North, at -alpha0 from the rotor axis at release, is identified from
    the observed coordinate alpha - alpha0. Defaults are the source's values.
    """


@group.command()
@parameter_options(api.SIMULATE_PARAMETERS)
@click.option("--output", "-o", "output", type=click.Path(dir_okay=False, path_type=Path), required=True,
              help="CSV file to write (columns t_s, alpha_rad).")
@json_option
def simulate(output, as_json, **raw):
    """Simulate a run-down and write the observation record (CSV: t_s, alpha_rad)."""
    values = parse_options(api.SIMULATE_PARAMETERS, raw)
    with options_named(api.SIMULATE_PARAMETERS):
        record = api.simulate_record(**values)
    path = write_record(output, record.time, record.observed)
    record.file = str(path)
    emit(record, as_json, inputs=values, files=[path])


@group.command()
@click.argument("record", type=click.Path(dir_okay=False, path_type=Path))
@parameter_options(api.IDENTIFY_PARAMETERS)
@out_option
@json_option
def identify(record, out_dir, as_json, **raw):
    """Identify north from RECORD.csv (columns t_s, alpha_rad).

    Known instrument values (lambda, Hm, J, latitude or omega_h) are given as
    options; unknown ones start from them (lsq) or centre the grid (grid).
    """
    values = parse_options(api.IDENTIFY_PARAMETERS, raw)
    time, observed = read_record(record)
    with options_named(api.IDENTIFY_PARAMETERS):
        estimate = api.identify_record(time, observed, **values)
    files = []
    if out_dir is not None:
        files = api.write_figures(estimate, out_dir, "north", values["lambda"], _nominal_b(values))
    emit(estimate, as_json, inputs={"record": str(record), **values}, files=files)


def _nominal_b(values):
    omega_h = api.resolve_omega_h(values["latitude"], values["omega_h"])
    return float(motion.directive_coefficient(values["hm"], omega_h, values["inertia"]))


@group.command()
@click.option("--unknowns", type=click.IntRange(2, 5), default=4, show_default=True,
              help="Unknowns to identify: 2, 3, 4 (the source's) or 5 (+ harmful torque).")
@click.option("--method", type=click.Choice(["lsq", "grid"]), default="lsq", show_default=True,
              help="lsq: variable projection; grid: three-stage grid refinement.")
@out_option
@json_option
def reproduce(unknowns, method, out_dir, as_json):
    """The source's machine experiment: Tables 1-3 re-run, and the identification."""
    result = api.reproduce(unknowns, method)
    files = []
    if out_dir is not None:
        files = api.write_figures(result.estimate, out_dir, "north", motion.SOURCE_LAMBDA, result.estimate.B)
    emit(result, as_json, inputs={"unknowns": unknowns, "method": method}, files=files)


@group.command()
@parameter_options(api.PARAMETERS)
@out_option
@json_option
def run(out_dir, as_json, **raw):
    """Simulate a run-down record and identify north from it (a user case)."""
    values = parse_options(api.PARAMETERS, raw)
    with options_named(api.PARAMETERS):
        result = api.run(**values)
    files = []
    if out_dir is not None:
        files = api.write_figures(result.estimate, out_dir, "north", values["lambda"], _nominal_b(values))
    emit(result, as_json, inputs=values, files=files)
