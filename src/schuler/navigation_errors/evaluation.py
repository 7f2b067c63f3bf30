"""What ``schuler errors run`` evaluates: its parameters, outputs and ``evaluate``.

One horizontal channel of a Schuler-tuned INS (Bollay 1966, equations (1)-(4)
of the teaching note and Problems 1-3; :mod:`~schuler.navigation_errors.single_channel`):
the position error of one error source on a flat Earth (x'' = g theta_1 + Delta_a)
and on a spherical Earth (x'' + (g/R) x = g theta_1 + Delta_a), errors computed -
true, positive in the direction the source pushes them.

Fidelities: ``simulated`` (default) takes the spherical error at the end of the
run from the exact simulation of the error equations (matrix exponential on the
output grid) and reports the largest difference from the closed form there;
``closed`` takes it from the closed form and leaves the difference NaN. A
simulation that departs from the closed form by more than
:data:`SIMULATION_TOLERANCE` of the error's size (far more Schuler periods than
the matrix exponential holds its accuracy over) raises a
:class:`~schuler.navigation_errors.results.SimulationAccuracyWarning`, which
a run in full (``histories=True``) also keeps in its ``warnings``. The
flat-Earth errors and the largest errors over the run are closed forms in both
(the largest spherical error is exact over continuous time, not sampled).

The errors are linear in the magnitude, so ``evaluate`` simulates each distinct
(source, Earth, speed, duration, output step) once for a unit magnitude and
scales it: a sweep or Monte Carlo costs one simulation per distinct grid, not
per case. The model has no random terms of its own: ``--monte-carlo`` draws only
what a scenario's distributions say.
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.geometry import grid_points, time_grid
from schuler.core.response import Histories
from schuler.exceptions import InvalidParameter
from schuler.memory import require
from schuler.navigation_errors.inputs import (
    EARTH_PARAMETERS,
    FLIGHT_TIME,
    GRID_NAMES,
    SOURCE_SI_UNITS,
    MagnitudeParameter,
    SourceParameters,
    earth_constant_arrays,
    magnitude_si,
)
from schuler.navigation_errors.results import SimulationAccuracyWarning
from schuler.navigation_errors.single_channel import (
    SOURCES,
    flat_error,
    maximum_error,
    simulate_error,
    spherical_error,
)
from schuler.params import Case, Parameter

MAX_DURATION = 1e9
"""Longest run, s (about 32 years: the closed forms stay finite for every allowed source and Earth)."""

POINTS_PER_RUN = 1000
"""Output steps of a run whose ``output_step`` is not set."""

SIMULATION_BYTES_PER_POINT = 480
"""Memory one output point of a simulated group holds: the engine's 5x5 transition matrix, states, outputs, the grid and
the closed form beside it (float64)."""

HISTORY_BYTES_PER_POINT = SIMULATION_BYTES_PER_POINT + 4 * 8
"""Memory one output point of a run in full holds: a simulation and the four histories."""

PARAMETERS = SourceParameters((
    Parameter("source", "", "drift", "Error source: tilt (level misalignment), velocity (initial velocity error), "
              "accelerometer (bias), drift (gyro drift rate) or azimuth (misalignment).", choices=SOURCES,
              kind="choice"),
    MagnitudeParameter("magnitude", "", None,
                       "Size of the error (>= 0); a bare number is in the source's unit: tilt and azimuth deg, "
                       "velocity ft/s, accelerometer g, drift deg/h (not set: Problem 3's 0.01 deg, 1 ft/s, "
                       "1e-4 g, 0.01 deg/h, 0.01 deg)."),
    Parameter("duration", "s", FLIGHT_TIME, "Length of the run.", minimum=0.0, exclusive_minimum=True,
              maximum=MAX_DURATION),
    Parameter("output_step", "s", None, "Output step (not set: duration / 1000; the simulation is exact between "
              "outputs).", minimum=0.0, exclusive_minimum=True),
    Parameter("speed", "m/s", "0.5 mi/s", "Vehicle speed V; the azimuth error grows with the range V t.",
              minimum=0.0, maximum=1e5),
    *EARTH_PARAMETERS,
), owner="errors", renamed={"step": "output_step"})
"""Every option of ``schuler errors run`` (and key of an ``errors`` scenario)."""

OUTPUTS = (
    Output("final_flat_m", "m", "ft", "flat-Earth error at the end of the run (closed form)"),
    Output("final_spherical_m", "m", "ft", "spherical-Earth error at the end of the run (simulated or closed form)"),
    Output("max_flat_m", "m", "ft", "largest |flat-Earth error| over the run (closed form)"),
    Output("max_spherical_m", "m", "ft", "largest |spherical-Earth error| over the run (closed form)"),
    Output("simulation_minus_closed_m", "m", "", "largest |simulated - closed-form| spherical error on the output "
           "grid (simulated only)"),
    Output("schuler_period_s", "s", "min", "Schuler period 2 pi sqrt(R / g)"),
    Output("radius_m", "m", "km", "Earth radius R used"),
    Output("gravity_m_s2", "m/s^2", "", "gravity g of the Schuler loop used"),
)

FIDELITIES = ("simulated", "closed")

SIMULATION_TOLERANCE = 1e-6
"""Largest |simulated - closed form| spherical error, as a fraction of the largest |closed form| on the grid, that
the simulation is trusted with. Both are exact, so they agree to rounding, which grows with the number of Schuler
periods: 1e-15 over a flight, 1e-12 over 200 periods, 1e-9 over 2e5 (the default Earth at 1e9 s); beyond this
tolerance the matrix exponential has lost the accuracy the engine states (a millionth)."""


def _magnitudes(sources: np.ndarray, column: np.ndarray) -> np.ndarray:
    """SI magnitudes of a batch: numbers are SI, text takes its source's unit, None or NaN its Problem 3 value."""
    if column.dtype.kind in "fiu":
        values = column.astype(float)
        unset = np.isnan(values)
        units = {SOURCE_SI_UNITS[source] for source in set(sources[~unset].tolist())}
        if len(units) > 1 and np.unique(values[~unset]).size == 1:
            # one SI number for sources of different units: a magnitude written for one source, swept over others
            raise InvalidParameter("magnitude", f"one value ({values[~unset][0]:g} in SI) for sources of different "
                                                f"units ({', '.join(sorted(units))}): leave magnitude unset (each "
                                                "source takes its Problem 3 value) or sweep it with the source")
        for source in set(sources[unset].tolist()):
            values[unset & (sources == source)] = magnitude_si(str(source), None)
        return values
    # each distinct (source, text) parsed once: unit parsing costs about 1 ms
    keys = list(zip(sources.tolist(), column.tolist()))
    resolved = {key: magnitude_si(str(key[0]), key[1]) for key in set(keys)}
    return np.array([resolved[key] for key in keys], dtype=float)


def _batch(cases: Cases) -> dict[str, np.ndarray]:
    """The batch in SI with every "not set" resolved: source, magnitude, R, g, V, duration, output step."""
    sources = np.asarray(cases["source"], dtype=object)
    R, g = earth_constant_arrays(np.asarray(cases["earth"], dtype=object), cases.float("radius"),
                                 cases.float("gravity"))
    duration = cases.float("duration")
    return {
        "source": sources,
        "magnitude": _magnitudes(sources, np.asarray(cases["magnitude"])),
        "radius": R,
        "gravity": g,
        "speed": cases.float("speed"),
        "duration": duration,
        "step": cases.value_or("output_step", duration / POINTS_PER_RUN),
    }


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    Closed forms are vectorised over the batch; the simulated fidelity runs one
    exact simulation per distinct (source, R, g, V for the azimuth source,
    duration, output step), for a unit magnitude, scaled per case.

    Parameters
    ----------
    cases : Cases
        A batch of validated cases (SI values; random terms from ``cases.random`` at ``cases.members``).
    histories : bool
        Also the first case in full (an :class:`~schuler.contract.Evaluation`): the flat, spherical and
        simulated errors over time (m, CSV ``errors_run_<source>``), ``source``, ``earth``, ``magnitude``
        (SI in the source's unit), ``speed_m_s``, ``duration_s`` and ``warnings``, what the run warned of.

    Examples
    --------
    >>> run = evaluate(Cases.from_case(PARAMETERS.case(source="velocity", earth="bollay")), histories=True)
    >>> round(run["max_spherical_m"][0] / 0.3048), list(run.histories["errors_run_velocity"].names)
    (805, ['flat_m', 'spherical_m', 'simulated_m'])
    """
    if histories:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SimulationAccuracyWarning)
            out = evaluate(cases)
        notes = [str(w.message) for w in caught if issubclass(w.category, SimulationAccuracyWarning)]
        for warning in caught:  # shown to the caller as they came, and kept in the result
            warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
        return _run_histories(cases, dict(out), notes)
    n = len(cases)
    batch = _batch(cases)
    points = grid_points(batch["duration"], batch["step"], names=GRID_NAMES)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    for source in set(batch["source"].tolist()):
        chosen = batch["source"] == source
        args = (batch["magnitude"][chosen], batch["duration"][chosen])
        R, g, V = batch["radius"][chosen], batch["gravity"][chosen], batch["speed"][chosen]
        out["final_flat_m"][chosen] = flat_error(source, *args, g, V)
        out["final_spherical_m"][chosen] = spherical_error(source, *args, R, g, V)
        out["max_flat_m"][chosen] = maximum_error(source, *args, R, g, V, earth="flat")
        out["max_spherical_m"][chosen] = maximum_error(source, *args, R, g, V)
    out["schuler_period_s"] = 2.0 * np.pi * np.sqrt(batch["radius"] / batch["gravity"])
    out["radius_m"] = batch["radius"]
    out["gravity_m_s2"] = batch["gravity"]
    if (cases.fidelity or FIDELITIES[0]) == "simulated" and n:
        _simulate_groups(batch, points, out)
    return out


def _simulate_groups(batch: dict[str, np.ndarray], points: np.ndarray, out: dict[str, np.ndarray]) -> None:
    """The simulated outputs, one simulation per distinct grid and model (errors are linear in the magnitude)."""
    require(float(points.max()) * SIMULATION_BYTES_PER_POINT, "this run", "`duration` or `output_step`")
    codes = np.array([SOURCES.index(s) for s in batch["source"]], dtype=float)
    # the speed shapes only the azimuth model
    speed = np.where(codes == SOURCES.index("azimuth"), batch["speed"], 0.0)
    keys = np.stack([codes, batch["radius"], batch["gravity"], speed, batch["duration"], batch["step"]], axis=1)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    worst: tuple[float, str, float, float, float] | None = None
    for k, (code, R, g, V, duration, step) in enumerate(unique):
        members = np.flatnonzero(inverse.ravel() == k)
        source = SOURCES[int(code)]
        t = time_grid(duration, step, names=GRID_NAMES, max_points=sys.maxsize)  # sized by require above
        simulated = simulate_error(source, 1.0, t, R, g, V)
        closed = spherical_error(source, 1.0, t, R, g, V)
        magnitude = batch["magnitude"][members]
        difference = float(np.max(np.abs(simulated - closed)))
        out["final_spherical_m"][members] = magnitude * simulated[-1]
        out["simulation_minus_closed_m"][members] = magnitude * difference
        scale = float(np.max(np.abs(closed)))
        if scale > 0 and difference > SIMULATION_TOLERANCE * scale and (worst is None or difference / scale > worst[0]):
            worst = (difference / scale, source, duration, 2.0 * np.pi * np.sqrt(R / g), step)
    if worst is not None:
        warnings.warn(_disagreement_message(*worst), SimulationAccuracyWarning, stacklevel=3)


def _disagreement_message(relative: float, source: str, duration: float, period: float, step: float) -> str:
    """What a simulation that lost its accuracy tells the user."""
    return (f"the simulated spherical error departs from the closed form by {relative:.2g} of the error's size "
            f"({source} source, {duration / period:,.3g} Schuler periods of {period:.3g} s in output steps of "
            f"{step:.3g} s), beyond the {SIMULATION_TOLERANCE:g} the simulation is accurate to: trust the closed "
            "form (--fidelity closed) or shorten --duration")


def member_bytes(case: Case) -> int:
    """Memory one Monte Carlo member holds while evaluated: a few floats per output (grids are per group).

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    return 64 * len(OUTPUTS) + 256


def _run_histories(cases: Cases, out: dict[str, np.ndarray], notes: list[str]) -> Evaluation:
    """The batch's first case in full: its outputs, the error histories (CSV ``errors_run_<source>``), extras."""
    fidelity = cases.fidelity or FIDELITIES[0]
    batch = {name: values[0] for name, values in _batch(cases).items()}
    count = grid_points(batch["duration"], batch["step"], names=GRID_NAMES)
    require(count * HISTORY_BYTES_PER_POINT, "this run", "`duration` or `output_step`")
    t = time_grid(batch["duration"], batch["step"], names=GRID_NAMES, max_points=sys.maxsize)  # sized above
    source, magnitude = str(batch["source"]), float(batch["magnitude"])
    R, g, V = float(batch["radius"]), float(batch["gravity"]), float(batch["speed"])
    channels = {"flat_m": flat_error(source, magnitude, t, g, V),
                "spherical_m": spherical_error(source, magnitude, t, R, g, V)}
    if fidelity == "simulated":
        channels["simulated_m"] = simulate_error(source, magnitude, t, R, g, V)
    histories = Histories(t, channels, dict.fromkeys(channels, "m"))
    extras = {"source": source, "earth": str(cases["earth"][0]), "magnitude": magnitude, "speed_m_s": V,
              "duration_s": float(batch["duration"]), "warnings": notes}
    return Evaluation(out, histories={f"errors_run_{source}": histories}, extras=extras)
