"""``schuler calibrate``: gyro drift calibration by alternating-sign torque pulses."""

from __future__ import annotations

import click

from schuler.cli.common import emit, json_option, options_named, out_option, parameter_options, parse_options
from schuler.drift_calibration.api import PARAMETERS, SYSTEM, write_figures


@click.group(name="calibrate")
def group():
    """Gyro drift calibration by alternating torque pulses, with autonomous azimuth (source 001)."""


@group.command()
@parameter_options(PARAMETERS)
@json_option
@out_option
def run(as_json, out_dir, **options):
    """One procedure: own drifts, Earth-rate component, azimuth and its error; --monte-carlo N for statistics."""
    values = parse_options(PARAMETERS, options)
    with options_named(PARAMETERS):
        result = SYSTEM.run(**values)
    files = write_figures(result, out_dir) if out_dir else []
    emit(result, as_json, inputs=values, files=files)


@group.command()
@json_option
def reproduce(as_json):
    """The source's case: latitude 70 deg, azimuth 80 deg, against its 0.34 % and 2 arcmin."""
    emit(SYSTEM.reproduce(), as_json)
