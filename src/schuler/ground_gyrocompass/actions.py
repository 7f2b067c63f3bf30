"""The ground gyrocompass's own commands: ``north identify RECORD`` and ``north simulate -o FILE``.

Both take SI values (and paths) and return a result that draws its figures
(:func:`~schuler.ground_gyrocompass.files.identification_figures`,
:func:`~schuler.ground_gyrocompass.files.record_figures`); the
files they read and write are handled here, never in the command line: records are CSV files with columns
``t_s`` (s since the rotor's release) and ``alpha_rad`` (the observed coordinate,
rad: alpha - alpha0 for the relative reading of Fedorov, Kikot and Shtefan (2020),
eq. (10), or alpha + c for absolute readings).
"""

from __future__ import annotations

from pathlib import Path

from schuler.contract import Action, Argument, Cases
from schuler.core.random import RandomStreams
from schuler.exceptions import SchulerError
from schuler.ground_gyrocompass.evaluation import (
    EXCLUSIVE,
    FIT_PARAMETERS,
    INSTRUMENT_PARAMETERS,
    MOTION_PARAMETERS,
    OBSERVATION_PARAMETERS,
    READING_PARAMETER,
    RECORD_BYTES_PER_SAMPLE,
    fit_bytes,
    identify_north,
    omega_h_of,
    record_window,
    records,
    truth_of,
)
from schuler.ground_gyrocompass.files import identification_figures, record_figures
from schuler.ground_gyrocompass.observations import read_record, write_record
from schuler.ground_gyrocompass.results import NorthIdentification, ObservationRecord
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet

IDENTIFY_PARAMETERS = ParameterSet((*INSTRUMENT_PARAMETERS, READING_PARAMETER, *FIT_PARAMETERS),
                                   owner="north identify", exclusive=EXCLUSIVE)
"""Options of ``schuler north identify``: the instrument's known or nominal values and the fit."""

SEED_PARAMETER = Parameter(
    "seed", "", 0, "Seed of the read-out noise (the record is member 0 of 'north run --monte-carlo N' with this seed).",
    minimum=0, kind="integer")
SIMULATE_PARAMETERS = ParameterSet(
    (*MOTION_PARAMETERS, *INSTRUMENT_PARAMETERS, *OBSERVATION_PARAMETERS, READING_PARAMETER, SEED_PARAMETER),
    owner="north simulate", exclusive=EXCLUSIVE)
"""Options of ``schuler north simulate``: the motion, the instrument, the read-out and the noise's seed."""

CSV_BYTES_PER_LINE = 8
"""The shortest line of a plausible record ("0,1e-4" and its newline), bytes."""
HELD_BYTES_PER_LINE = 80
"""What reading holds per line until the arrays are built: two Python floats and their list slots."""


def identify_record(record: Path, **values) -> NorthIdentification:
    """Identify north from a CSV record (``north identify RECORD``), SI keywords of :data:`IDENTIFY_PARAMETERS`.

    Parameters
    ----------
    record : Path
        CSV file with columns ``t_s`` (s since release) and ``alpha_rad`` (observed coordinate, rad).
    **values
        Options of :data:`IDENTIFY_PARAMETERS` by name, in SI: ``decay_rate`` 1/s, ``hm`` N m s, ``inertia``
        kg m^2, ``latitude`` rad or ``omega_h`` rad/s; ``reading``, ``unknowns`` and ``method`` as choices.
        Missing ones take their defaults.

    Returns
    -------
    NorthIdentification
        The identified north and the other parameters with their standard errors.

    Raises
    ------
    InvalidParameter
        Named after the file (and line) when it is missing, not UTF-8 text, or not
        a valid record; named after the option for a bad value.
    MemoryBudgetExceeded
        When the record is too long to read or to identify within the memory budget.
    """
    case = IDENTIFY_PARAMETERS.case(values)
    record = Path(record)
    if record.is_file():
        require(record.stat().st_size / CSV_BYTES_PER_LINE * HELD_BYTES_PER_LINE, f"reading {record}",
                "the record's length")
    time, observed = read_record(record)
    require(fit_bytes(time.size, case["method"], case["unknowns"]), f"identifying {record}",
            "the record's length or `method`")
    estimate = identify_north(time, observed, case["unknowns"], decay_rate=case["decay_rate"], hm=case["hm"],
                              inertia=case["inertia"], omega_h=float(omega_h_of(Cases.from_case(case))[0]),
                              reading=case["reading"], method=case["method"])
    return NorthIdentification.from_estimate(estimate)


def simulate_record(output: Path, **values) -> ObservationRecord:
    """Simulate a run-down record and write it to ``output`` (``north simulate -o FILE``), atomically.

    The record is made as ``north run`` makes it (closed form (9), read-out noise
    and quantisation); its noise is that of member 0 of a Monte Carlo with the same
    seed. SI keywords of :data:`SIMULATE_PARAMETERS`.

    Parameters
    ----------
    output : Path
        CSV file to write (columns ``t_s`` and ``alpha_rad``).
    **values
        Options of :data:`SIMULATE_PARAMETERS` by name, in SI: ``alpha0`` rad, ``alpha0_dot`` rad/s,
        ``torque`` N m, ``decay_rate`` 1/s, ``hm`` N m s, ``inertia`` kg m^2, ``latitude`` rad or ``omega_h``
        rad/s, ``duration`` and ``output_step`` s, ``readout_noise``, ``quantisation`` and ``offset`` rad;
        ``reading`` a choice, ``seed`` an integer. Missing ones take their defaults.

    Returns
    -------
    ObservationRecord
        The record written (times, observed coordinate) and the truth it was made from.

    Raises
    ------
    SchulerError
        When ``output`` cannot be written (named as given, never a temporary file).
    """
    case = SIMULATE_PARAMETERS.case(values)
    output = Path(output)
    cases = Cases.from_case(Case({name: case[name] for name in case if name != "seed"}), members=[0],
                            random=RandomStreams(case["seed"]))
    time = record_window(cases, RECORD_BYTES_PER_SAMPLE)
    truth = truth_of(cases)
    observed = records(time, cases, truth, "closed")[0]
    try:
        write_record(output, time, observed)
    except OSError as error:
        raise SchulerError(f"cannot write {output}: {error.strerror or error}") from None
    return ObservationRecord(
        record_file=str(output), samples=time.size, duration_s=float(time[-1]), output_step_s=case["output_step"],
        reading=case["reading"], true_north_rad=-case["alpha0"], omega_h=float(truth["omega_h"][0]),
        directive_coefficient=float(truth["coefficient"][0]), readout_noise_rad=case["readout_noise"],
        seed=case["seed"], time=time, observed=observed, files=[output])


ACTIONS = (
    Action("identify",
           "Identify north from an observed run-down record (CSV, columns t_s and alpha_rad).\n\n"
           "The instrument's known values (or nominal starts for identified ones) are options; "
           "--unknowns chooses what is identified, --method the estimator.",
           identify_record, IDENTIFY_PARAMETERS,
           arguments=(Argument("record", "CSV record with columns t_s and alpha_rad", "RECORD"),),
           figures=identification_figures),
    Action("simulate",
           "Simulate a run-down record and write it as CSV (columns t_s, alpha_rad).\n\n"
           "The true motion is the closed form (9); --readout-noise and --seed set the read-out noise.",
           simulate_record, SIMULATE_PARAMETERS, output_file="CSV file to write the record to.",
           figures=record_figures),
)
"""The commands ``schuler north identify`` and ``schuler north simulate``."""
