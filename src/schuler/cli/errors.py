"""``schuler errors``: Schuler-tuned INS error propagation (Bollay, "The Story of 84 Minutes")."""

from __future__ import annotations

import json

import click

from schuler import __version__
from schuler.cli.common import emit, json_option, options_named, out_option, parameter_options, parse_options, warn
from schuler.navigation_errors import api
from schuler.navigation_errors.results import DISPLAY_UNITS

units_option = click.option(
    "--units", "units", type=click.Choice(DISPLAY_UNITS), default=None,
    help="Length unit of the human-readable output (JSON stays SI, or feet where the key says so).",
)


@click.group(name="errors")
def group():
    """Schuler-tuned INS errors: five sources on a flat and a spherical Earth, vertical channel, periods."""


@group.command(short_help="One error source versus time (flat, spherical, simulated).")
@parameter_options(api.PARAMETERS)
@units_option
@json_option
@out_option
def run(units, as_json, out_dir, **options):
    """Error of one source versus time: flat and spherical closed forms and the simulated error equations.

    Example: schuler errors run --source drift --magnitude "0.01 deg/h" --duration "6 h" --step "60 s"
    """
    inputs = parse_options(api.PARAMETERS, options)
    inputs["magnitude"] = api.parse_magnitude(inputs["source"], inputs["magnitude"], label="--magnitude")
    with options_named(api.PARAMETERS):
        result = api.run(**inputs)
    result.display_unit = units or "m"
    files = []
    if out_dir is not None:
        files = api.write_run_outputs(result, out_dir, result.display_unit)
    emit(result, as_json, inputs=inputs, files=files)


@group.command(short_help="Bollay's Problem 3 table and hover error, printed vs computed.")
@units_option
@json_option
def reproduce(units, as_json):
    """Bollay's Problem 3 table (flat vs spherical at 10,120 s and maxima) and the Problem 4 hover error.

    Each row shows the source's printed value beside the recomputed one, whether they agree within the
    source's rounding, and why they differ where they do.
    """
    result = api.reproduce()
    result.display_unit = units or "ft"
    emit(result, as_json)


@group.command(short_help="Problem 3's figures (PNG and SVG).")
@click.option("--out", "out_dir", type=click.Path(file_okay=False), required=True,
              help="Folder for the figures (created if missing).")
@click.option("--points", type=click.IntRange(min=3, max=100_001), default=1013, show_default=True,
              help="Time points over 0..10,120 s.")
@units_option
@json_option
def plot(out_dir, points, units, as_json):
    """Problem 3's figures: each error versus time, flat vs spherical, and a log-scale overview (PNG, SVG)."""
    files = api.write_problem3_figures(out_dir, units or "ft", points)
    files += api.write_vertical_figure(out_dir, units or "ft")
    if as_json:
        click.echo(json.dumps({"schuler_version": __version__, "files": [str(f) for f in files]}, indent=2))
    else:
        click.echo(f"wrote {len(files)} files to {out_dir}")


@group.command(short_help="Vertical channel: divergence vs baro-aided loop.")
@parameter_options(api.VERTICAL_PARAMETERS)
@units_option
@json_option
def vertical(units, as_json, **options):
    """Vertical channel: pure-inertial divergence (Problem 4) vs a baro-aided 2nd/3rd-order loop."""
    inputs = parse_options(api.VERTICAL_PARAMETERS, options)
    with options_named(api.VERTICAL_PARAMETERS):
        result = api.vertical(**inputs)
    result.display_unit = units or "m"
    emit(result, as_json, inputs=inputs)


@group.command(short_help="Effective Schuler period under thrust or fast flight.")
@parameter_options(api.PERIOD_PARAMETERS)
@json_option
def period(as_json, **options):
    """Effective Schuler period under vertical thrust n g and in level flight at speed V (source footnote)."""
    inputs = parse_options(api.PERIOD_PARAMETERS, options)
    with options_named(api.PERIOD_PARAMETERS):
        result = api.period(**inputs)
    if result.speed_m_s >= result.orbital_speed_m_s:
        warn(f"--speed {result.speed_m_s:g} m/s is at or above the orbital speed {result.orbital_speed_m_s:.0f} m/s: "
             "no restoring force, the period is infinite")
    emit(result, as_json, inputs=inputs)
