"""``schuler vertical``: gyro vertical with integral correction measuring velocity (Drozdovich, 1959)."""

from __future__ import annotations

import click

from schuler.cli.common import emit, json_option, options_named, out_option, parameter_options, parse_options
from schuler.gyro_vertical import api


@click.group(name="vertical")
def group():
    """Gyro vertical with integral correction: velocity errors on a great circle, modes, friction."""


@group.command()
@parameter_options(api.PARAMETERS)
@json_option
@out_option
def run(as_json, out_dir, **options):
    """Simulate one case: tilts, measured and true velocity, the quasi-steady error and the split periods.

    Example: schuler vertical run --latitude 60 --speed 10 --earth drozdovich --duration "48 h" --out results
    """
    inputs = parse_options(api.PARAMETERS, options)
    with options_named(api.PARAMETERS):
        result = api.run(**inputs)
    files = api.write_run_figures(result.analysis, out_dir) if out_dir is not None else []
    emit(result, as_json, inputs=inputs, files=files)


@group.command()
@json_option
@out_option
def reproduce(as_json, out_dir):
    """The source's worked example (60 deg, 10 m/s, R = 6.4e6 m) with its errata flagged.

    Recomputes W*, the steady tilt and the velocity error (printed 0.67 m/s, really 0.557), the split
    Schuler periods (printed "24 h and 84.4 min") from the eigenvalues and from a 48-h simulation, the
    friction estimate, and the effect of compensating the transport and Coriolis terms.
    """
    result = api.reproduce()
    files = []
    if out_dir is not None:
        files = api.write_run_figures(result.analysis, out_dir, "vertical_example", compensated=result.compensated)
    emit(result, as_json, files=files)


@group.command()
@parameter_options(api.FRICTION_PARAMETERS)
@json_option
@out_option
def friction(as_json, out_dir, **options):
    """Coulomb friction in the gimbal bearings (30)-(32): stick/slip, the dead zone +-R q, the slip growth.

    Example: schuler vertical friction --dead-zone 0.01 --initial-beta "0.2 arcsec" --out results
    """
    inputs = parse_options(api.FRICTION_PARAMETERS, options)
    with options_named(api.FRICTION_PARAMETERS):
        result = api.run_friction(**inputs)
    files = []
    if out_dir is not None:
        from schuler.gyro_vertical.plots import plot_friction
        from schuler.io import save_figure_formats

        figure = plot_friction(result.response, (result.q_1, result.q_2), result.dead_zone_x / result.q_1)
        files = save_figure_formats(figure, out_dir / "vertical_friction")
    emit(result, as_json, inputs=inputs, files=files)
