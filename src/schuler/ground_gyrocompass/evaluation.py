"""What the ground gyrocompass system evaluates: its parameters, outputs and ``evaluate``.

A case is one run-down record: the true motion of the sensitive element,
alpha(t) = alpha0 u1(t) + alpha0_dot u2(t) + m u3(t) (eq. (9) of Fedorov, Kikot
and Shtefan (2020), with the torque's particular solution, see :mod:`.motion`),
sampled every ``output_step`` over ``duration`` and read as the source's relative
coordinate alpha - alpha0 (eq. (10)) or as absolute readings alpha + c. North is
then identified from the record by the production estimator (:func:`identify`,
what ``schuler north identify`` runs) with 2 to 5 unknowns.

Frames and signs: alpha is the angle of the rotor axis from north about the
vertical suspension axis, positive in the sense in which Omega_h precesses it back
to the meridian (eq. (1)); north is at -alpha0 from the rotor axis at release.
Errors are computed - true (``north_error_rad``).

Random terms: the white read-out noise (``readout_noise``). The nominal case
(``cases.random is None``) identifies north from the noise-free record and gives,
beside it, the standard error predicted for the given noise and quantisation by
the linearised covariance sigma^2 (J^T J)^-1 at the true parameters
(:func:`~.monte_carlo.predicted_errors`). Members of a Monte Carlo draw their noise
series from ``cases.random.normal_series("readout_noise", member, 0, samples)``,
so a member's record depends only on (seed, member), never on chunking.

A run (``evaluate`` with ``histories``) is the first case in full: its
outputs, the record and the fit to it (histories ``north_record_fit``), and
beside them ``unknowns``, ``method``, ``reading``, ``readout_noise_rad`` and
``true_north_rad``.

Fidelities: ``closed`` (default) makes the record from the closed form (9);
``simulated`` integrates eqs. (1)-(2) numerically (DOP853), as the source's
simulator did. They agree to 1e-9 rad (the tests check it).

References
----------
Fedorov, V. N.; Kikot, V. V.; Shtefan, N. I., "Determination of meridian position
by a two-step ground gyrocompass during natural run-down of its rotor", Mechanics
of Gyroscopic Systems, no. 40, 2020, doi:10.20535/0203-3771402020249107
(:data:`schuler.references.FEDOROV_2020`).
"""

from __future__ import annotations

import math
import sys

import numpy as np

from schuler.contract import Cases, Evaluation, Output
from schuler.core.geometry import grid_points, horizontal_earth_rate, time_grid
from schuler.exceptions import IdentificationError, InvalidParameter
from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.estimate import NorthEstimate, identify
from schuler.ground_gyrocompass.monte_carlo import predicted_errors
from schuler.ground_gyrocompass.observations import observe
from schuler.ground_gyrocompass.results import RECORD_FIT, record_fit
from schuler.memory import require
from schuler.params import Case, Parameter, ParameterSet

MOTION_PARAMETERS = (
    # the source's 3.69 pi/540 rad, as a number: quantity text is a number and a unit, not an expression
    Parameter("alpha0", "rad", motion.SOURCE_ALPHA0,
              "True initial angle alpha0 of the rotor axis from north (small angles).", minimum=-0.5, maximum=0.5),
    Parameter("alpha0_dot", "rad/s", motion.SOURCE_ALPHA0_DOT, "True initial azimuth rate.",
              minimum=-0.01, maximum=0.01),
    Parameter("torque", "N*m", 0.0, "Constant harmful torque M about the suspension axis (simulated)."),
)
INSTRUMENT_PARAMETERS = (
    Parameter("decay_rate", "1/s", motion.SOURCE_LAMBDA,
              "Decay rate lambda of the rotor's angular momentum, H = H_m exp(-lambda t) (known, or the nominal "
              "start when identified).", minimum=0, exclusive_minimum=True),
    Parameter("hm", "N*m*s", motion.SOURCE_HM,
              "Initial rotor angular momentum H_m (known, or nominal when identified).", minimum=0,
              exclusive_minimum=True),
    Parameter("inertia", "kg*m^2", motion.SOURCE_INERTIA, "Moment of inertia J about the suspension axis.",
              minimum=0, exclusive_minimum=True),
    Parameter("latitude", "deg", None, "Latitude of the site: Omega_h = Omega cos(latitude) (not set: --omega-h).",
              minimum=-90, maximum=90),
    Parameter("omega_h", "rad/s", None,
              "Horizontal Earth rate Omega_h (not set: from --latitude, else the source's 3.65e-5 rad/s).",
              minimum=0, exclusive_minimum=True),
)
OBSERVATION_PARAMETERS = (
    Parameter("duration", "s", motion.SOURCE_DURATION, "Observation window from the release.",
              minimum=0, exclusive_minimum=True),
    Parameter("output_step", "s", motion.SOURCE_STEP, "Sampling step of the record.", minimum=0,
              exclusive_minimum=True),
    Parameter("readout_noise", "arcsec", 0.0,
              "Standard deviation of the white read-out noise (Monte Carlo members draw it; the nominal case is "
              "noise-free and reports the standard error it predicts).", minimum=0),
    Parameter("quantisation", "arcsec", 0.0, "Read-out resolution (0: none).", minimum=0),
    Parameter("offset", "rad", 0.0, "Offset c of absolute readings (absolute reading only)."),
)
READING_PARAMETER = Parameter(
    "reading", "", "relative", "Observed coordinate: alpha - alpha0 (relative, eq. (10)) or alpha + offset (absolute).",
    choices=("relative", "absolute"), kind="choice")
FIT_PARAMETERS = (
    Parameter("unknowns", "", 4, "Unknowns: 2 (alpha0, rate), 3 (+decay rate), 4 (+H_m), 5 (+harmful torque).",
              minimum=2, maximum=5, kind="integer"),
    Parameter("method", "", "lsq", "lsq: variable-projection least squares; grid: the source's 3-stage grid.",
              choices=("lsq", "grid"), kind="choice"),
)
EXCLUSIVE = (("latitude", "omega_h"),)

PARAMETERS = ParameterSet(
    (*MOTION_PARAMETERS, *INSTRUMENT_PARAMETERS, *OBSERVATION_PARAMETERS, READING_PARAMETER, *FIT_PARAMETERS),
    owner="north", exclusive=EXCLUSIVE,
    renamed={"lambda": "decay_rate", "step": "output_step", "noise": "readout_noise"})
"""Every option of ``schuler north run`` (and key of a ``north`` scenario)."""

OUTPUTS = (
    Output("north_rad", "rad", "deg", "identified north, from the rotor axis at release (-alpha0)"),
    Output("north_error_rad", "rad", "arcsec", "identified minus true north"),
    Output("north_std_predicted_rad", "rad", "arcsec",
           "standard error of north predicted for the read-out noise and quantisation (linearised)"),
    Output("north_std_rad", "rad", "arcsec", "standard error of north from the fit's residuals"),
    Output("identified_alpha0_rad", "rad", "", "identified initial angle alpha0"),
    Output("identified_alpha0_dot_rad_s", "rad/s", "", "identified initial azimuth rate"),
    Output("identified_decay_rate", "1/s", "", "identified (or known) decay rate lambda"),
    Output("identified_directive_coefficient", "1/s^2", "", "identified (or known) B = H_m Omega_h / J"),
    Output("identified_hm", "N*m*s", "", "identified (or known) H_m = B J / Omega_h"),
    Output("identified_torque", "N*m", "", "identified harmful torque (0 unless 5 unknowns)"),
    Output("identified_offset_rad", "rad", "", "identified reading offset (0 for the relative reading)"),
    Output("misfit_rad2", "rad^2", "", "sum of squared residuals F"),
    Output("residual_rms_rad", "rad", "arcsec", "root mean square of the residuals"),
    Output("omega_h", "rad/s", "", "horizontal Earth rate Omega_h of the case"),
    Output("samples", "1", "", "samples in the record"),
    Output("model_evaluations", "1", "", "model evaluations of the estimator (grid cells for the grid)"),
    Output("converged", "1", "", "1 when the estimator converged, 0 when it stopped or failed"),
)

FIDELITIES = ("closed", "simulated")

RECORD_BYTES_PER_SAMPLE = 8 * 24
"""Bytes per sample of one record while a batch of records is made: the basis and its
derivatives (9 columns), the predicted errors' Jacobian (up to 7), the motion, the
noise, the observed coordinate, the time and slack."""

LSQ_BYTES_PER_SAMPLE = 8 * 60
"""Bytes per sample variable projection holds at its peak: the design, its derivatives,
Q and the Bessel intermediates, about 60 columns (measured: 390-450 bytes)."""

GRID_PAIRS = {2: 1, 3: 21, 4: 21 * 21, 5: 21 * 21}
"""(lambda, B) pairs of the grid estimator's first stage for each number of unknowns."""


def fit_bytes_per_sample(method: str, unknowns: int) -> int:
    """Bytes per sample one identification holds at its peak.

    The grid evaluates the basis on every (lambda, B) pair of a stage at once,
    16 columns each (measured: 210 bytes for 2 unknowns, 26 kB for 4, 47 kB for 5).

    Parameters
    ----------
    method : {"lsq", "grid"}
        The estimator: variable-projection least squares or the source's grid.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified.

    Returns
    -------
    int
        Bytes per sample of the record.
    """
    if method == "grid":
        return 8 * (30 + 16 * GRID_PAIRS[unknowns])
    return LSQ_BYTES_PER_SAMPLE


BATCH_BYTES = 64 * 2**20
"""Records made at once in a batch are limited to this many bytes."""


def sample_count(duration: float, step: float) -> float:
    """Samples of a record of ``duration`` every ``step`` (the rule of :func:`~schuler.core.geometry.time_grid`).

    Parameters
    ----------
    duration : float
        Observation window from the release, s.
    step : float
        Sampling step, s.

    Returns
    -------
    float
        Number of samples (a float: a huge request can be sized, then refused).
    """
    return grid_points(duration, step, names=("duration", "output_step"))


def fit_bytes(samples: int, method: str, unknowns: int) -> int:
    """Memory one identification of a record of ``samples`` holds at its peak, bytes.

    Parameters
    ----------
    samples : int
        Number of samples in the record.
    method : {"lsq", "grid"}
        The estimator: variable-projection least squares or the source's grid.
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified.

    Returns
    -------
    int
        Bytes (making the record and fitting it).
    """
    return samples * (RECORD_BYTES_PER_SAMPLE + fit_bytes_per_sample(method, unknowns))


def member_bytes(case: Case) -> int:
    """Memory one Monte Carlo member holds while its record is made (the fits run one at a time).

    Parameters
    ----------
    case : Case
        A validated case (SI values).
    """
    return int(sample_count(case["duration"], case["output_step"]) * RECORD_BYTES_PER_SAMPLE)


def omega_h_of(cases: Cases) -> np.ndarray:
    """The horizontal Earth rate Omega_h of each case, rad/s.

    Omega cos(latitude) where the latitude is set, ``omega_h`` where that is set,
    otherwise the source's 3.65e-5 rad/s (Fedorov et al. (2020), before Table 1).

    Parameters
    ----------
    cases : Cases
        The cases (validated SI arrays): ``latitude`` (rad) and ``omega_h`` (rad/s) where set.

    Returns
    -------
    ndarray (n,)
        Omega_h of each case, rad/s.

    Raises
    ------
    InvalidParameter
        A case sets both (the options exclude each other).
    NotObservable
        A latitude of +-90 deg: no horizontal Earth rate, north is undefined.
    """
    latitude, omega_h = cases.is_set("latitude"), cases.is_set("omega_h")
    if np.any(latitude & omega_h):
        raise InvalidParameter("latitude", "cannot be combined with omega_h; give one of them")
    values = np.where(omega_h, cases.value_or("omega_h", 0.0), motion.SOURCE_OMEGA_H)
    if np.any(latitude):
        values[latitude] = horizontal_earth_rate(cases.float("latitude")[latitude])
    return values


def truth_of(cases: Cases) -> dict[str, np.ndarray]:
    """The true motion's parameters of each case, named as the estimator names them.

    Parameters
    ----------
    cases : Cases
        The cases (validated SI arrays of :data:`PARAMETERS`: ``alpha0`` rad, ``alpha0_dot`` rad/s,
        ``decay_rate`` 1/s, ``hm`` N m s, ``inertia`` kg m^2, ``torque`` N m, ``offset`` rad, and the site).

    Returns
    -------
    dict of ndarray (n,)
        ``alpha0`` (rad), ``alpha0_dot`` (rad/s), ``decay_rate`` lambda (1/s),
        ``coefficient`` B = H_m Omega_h / J (1/s^2, eq. (3)), ``specific_torque``
        m = M / J (rad/s^2), ``offset`` (rad), ``omega_h`` (rad/s).
    """
    omega_h = omega_h_of(cases)
    inertia = cases.float("inertia")
    return {
        "alpha0": cases.float("alpha0"),
        "alpha0_dot": cases.float("alpha0_dot"),
        "decay_rate": cases.float("decay_rate"),
        "coefficient": np.asarray(motion.directive_coefficient(cases.float("hm"), omega_h, inertia), dtype=float),
        "specific_torque": cases.float("torque") / inertia,
        "offset": cases.float("offset"),
        "omega_h": omega_h,
    }


def record_window(cases: Cases, bytes_per_sample: int) -> np.ndarray:
    """The sample times of cases that share duration and output step, s.

    Refuses (:func:`~schuler.memory.require`) before allocating when a record of
    ``bytes_per_sample`` per sample would exceed the memory budget.

    Parameters
    ----------
    cases : Cases
        Cases of one ``duration`` and ``output_step`` (s; the first case's are used).
    bytes_per_sample : int
        Memory held per sample of the record while it is made and fitted, bytes.

    Returns
    -------
    ndarray (samples,)
        Sample times from the release, s (:func:`~schuler.core.geometry.time_grid`).

    Raises
    ------
    InvalidParameter
        An output step longer than the duration (MemoryBudgetExceeded: a record over the budget).
    """
    duration, step = float(cases.float("duration")[0]), float(cases.float("output_step")[0])
    if step > duration:
        raise InvalidParameter("output_step", f"{step:g} s is longer than the duration {duration:g} s")
    require(sample_count(duration, step) * bytes_per_sample, "this run", "`duration` or `output_step`")
    return time_grid(duration, step, names=("duration", "output_step"), max_points=sys.maxsize)


def true_motion(time: np.ndarray, truth: dict[str, np.ndarray], fidelity: str) -> np.ndarray:
    """alpha(t_k) of each case, shape (cases, samples), rad: closed form (9) or numerical integration.

    Parameters
    ----------
    time : ndarray (samples,)
        Sample times since the release, s.
    truth : dict of str to ndarray (cases,)
        :func:`truth_of` the cases: ``alpha0`` rad, ``alpha0_dot`` rad/s, ``decay_rate`` 1/s,
        ``coefficient`` 1/s^2, ``specific_torque`` rad/s^2.
    fidelity : {"closed", "simulated"}
        Closed form (9), or numerical integration of eqs. (1)-(2).

    Returns
    -------
    ndarray (cases, samples)
        The true angle alpha of the rotor axis from north, rad.

    Raises
    ------
    InvalidParameter
        A decay too slow for the closed form's phase, or a window past the rotor's run-down.
    """
    # the estimator fits the closed form (9), whichever way the record is made: a decay so slow that
    # its Bessel arguments lose their phase is refused
    motion.check_closed_form_reach(truth["decay_rate"], truth["coefficient"])
    # the closed form, which the estimator fits, needs z(t) = z0 exp(-lambda t / 2) > 0 (eq. (5)): after
    # lambda t of about 1500 it underflows, Y0(z) is infinite, and neither record nor fit can be computed
    z_end, _ = motion.bessel_argument(time[-1], truth["decay_rate"], truth["coefficient"])
    with np.errstate(all="ignore"):
        angle = _motion(time, truth, fidelity) if np.all(z_end > 0.0) else np.full((z_end.size, time.size), np.nan)
    if not np.all(np.isfinite(angle)):
        worst = float(np.max(truth["decay_rate"]) * time[-1])
        raise InvalidParameter("duration", f"{time[-1]:g} s: the closed form (9) is not finite once the rotor has "
                                           f"run down (lambda t = {worst:.3g}); observe for a shorter time")
    return angle


def _motion(time: np.ndarray, truth: dict[str, np.ndarray], fidelity: str) -> np.ndarray:
    if fidelity == "simulated":
        angle = np.stack([motion.simulate(time, *(truth[k][i] for k in
                                                  ("alpha0", "alpha0_dot", "decay_rate", "coefficient",
                                                   "specific_torque")))
                          for i in range(truth["alpha0"].size)])
    else:
        torque = bool(np.any(truth["specific_torque"] != 0.0))
        u = motion.basis(time, truth["decay_rate"][:, None], truth["coefficient"][:, None], torque=torque,
                         derivatives=False).angle
        angle = (truth["alpha0"][:, None] * u[0] + truth["alpha0_dot"][:, None] * u[1]
                 + truth["specific_torque"][:, None] * u[2])
    return angle


def records(time: np.ndarray, cases: Cases, truth: dict[str, np.ndarray], fidelity: str) -> np.ndarray:
    """The observed coordinate of each case: what the read-out gives, rad.

    Parameters
    ----------
    time : ndarray (samples,)
        Sample times since the release, s.
    cases : Cases
        The cases (one reading for all); with ``cases.random`` set, member
        ``cases.members[i]`` draws its read-out noise from the stream
        ``"readout_noise"``, samples 0 .. samples - 1.
    truth : dict
        :func:`truth_of` the cases.
    fidelity : {"closed", "simulated"}

    Returns
    -------
    ndarray (cases, samples)
        alpha - alpha0 (relative reading, eq. (10)) or alpha + c (absolute), plus
        the noise, rounded to the quantisation step.
    """
    angle = true_motion(time, truth, fidelity)
    if cases.random is not None:
        sigma = cases.float("readout_noise")
        angle = angle + sigma[:, None] * cases.random.normal_series("readout_noise", cases.members, 0, time.size)
    reading = str(cases["reading"][0])
    quantisation = cases.float("quantisation")
    return np.stack([observe(angle[i], truth["alpha0"][i], quantisation=float(quantisation[i]), reading=reading,
                             offset=float(truth["offset"][i])) for i in range(len(cases))])


def evaluate(cases: Cases, histories: bool = False) -> dict[str, np.ndarray] | Evaluation:
    """Every output of :data:`OUTPUTS` for a batch of cases (SI arrays of length ``len(cases)``).

    Parameters
    ----------
    cases : Cases
        Every parameter of :data:`PARAMETERS` as arrays; ``cases.random`` None
        for the nominal (noise-free) records, else the streams members draw from.
    histories : bool
        Whether to give the first case in full (an :class:`~schuler.contract.Evaluation`): its record and
        fit as the histories ``north_record_fit`` (rad against ``t_s``) and the extras of the module notes.

    Returns
    -------
    dict of ndarray or Evaluation
        One array per :class:`~schuler.contract.Output` of :data:`OUTPUTS`.

    Raises
    ------
    IdentificationError
        With ``histories``, when the first case's record does not determine the unknowns.

    Notes
    -----
    Cases are grouped by what fixes the shape of the computation (duration, output
    step, unknowns, method, reading); each group's records are made in batches and
    identified one by one by the production estimator. A record the estimator
    cannot identify (:class:`~schuler.exceptions.IdentificationError`) gives NaN
    estimates and ``converged`` 0, except the first case's with ``histories``, which raises.

    Examples
    --------
    >>> from schuler.contract import Cases
    >>> run = evaluate(Cases.from_case(PARAMETERS.case(unknowns=2)), histories=True)
    >>> round(math.degrees(run["north_rad"][0]), 6), list(run.histories["north_record_fit"].names)
    (-1.23, ['observed_rad', 'fitted_rad', 'residual_rad'])
    """
    n = len(cases)
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    first: NorthEstimate | IdentificationError | None = None
    fidelity = cases.fidelity or FIDELITIES[0]
    for index, group in cases.groups("duration", "output_step", "unknowns", "method", "reading"):
        per_sample = fit_bytes_per_sample(str(group["method"][0]), int(group["unknowns"][0]))
        time = record_window(group, RECORD_BYTES_PER_SAMPLE + per_sample)
        batch = max(1, BATCH_BYTES // (time.size * RECORD_BYTES_PER_SAMPLE))
        for start in range(0, len(group), batch):
            part = group.take(np.arange(start, min(start + batch, len(group))))
            values, fits = _evaluate_batch(time, part, fidelity)
            where = index[start:start + len(part)]
            for name, array in values.items():
                out[name][where] = array
            if 0 in where:
                first = fits[int(np.flatnonzero(where == 0)[0])]
    if not histories:
        return out
    if isinstance(first, IdentificationError):
        raise first
    assert first is not None
    return _run(cases, out, first)


def _run(cases: Cases, outputs: dict[str, np.ndarray], estimate: NorthEstimate) -> Evaluation:
    """The first case in full: its outputs (counts and the flag as such), record and fit, and what it was."""
    case = cases.case(0)
    # a run's counts read as counts and its flag as a flag, where a batch carries them as floats
    outputs = {**outputs, "converged": outputs["converged"].astype(bool)}
    for name in ("samples", "model_evaluations"):
        if np.all(np.isfinite(outputs[name])):
            outputs[name] = outputs[name].astype(np.int64)
    extras = {"unknowns": case["unknowns"], "method": case["method"], "reading": case["reading"],
              "readout_noise_rad": case["readout_noise"], "true_north_rad": -case["alpha0"]}
    return Evaluation(outputs, histories={RECORD_FIT: record_fit(estimate.time, estimate.observed,
                                                                 estimate.residuals)},
                      extras=extras, units={"unknowns": "1"})


def _evaluate_batch(time, cases: Cases, fidelity: str):
    truth = truth_of(cases)
    unknowns, method, reading = int(cases["unknowns"][0]), str(cases["method"][0]), str(cases["reading"][0])
    needed = unknowns + (reading == "absolute")
    if time.size < needed:
        raise InvalidParameter("unknowns", f"{unknowns} unknowns ({reading} reading) need at least {needed} samples; "
                                           f"the record has {time.size} (lengthen the duration or shorten the step)")
    observed = records(time, cases, truth, fidelity)
    n = len(cases)
    predicted = predicted_errors(
        {k: v for k, v in truth.items() if k != "omega_h"}, cases.float("duration"), cases.float("output_step"),
        cases.float("readout_noise"), cases.float("quantisation"), unknowns, reading)["alpha0_std"]
    out = {output.name: np.full(n, np.nan) for output in OUTPUTS}
    out.update(north_std_predicted_rad=predicted, omega_h=truth["omega_h"], samples=np.full(n, float(time.size)),
               converged=np.zeros(n))
    # per case its estimate, or the error that refused its record
    estimates: list[NorthEstimate | IdentificationError] = []
    for i in range(n):
        try:
            estimate = identify_north(time, observed[i], unknowns, decay_rate=float(truth["decay_rate"][i]),
                                      hm=float(cases.float("hm")[i]), inertia=float(cases.float("inertia")[i]),
                                      omega_h=float(truth["omega_h"][i]), reading=reading, method=method)
        except IdentificationError as error:
            estimates.append(error)
            continue
        estimates.append(estimate)
        for name, value in estimate_outputs(estimate).items():
            out[name][i] = value
        out["north_error_rad"][i] = truth["alpha0"][i] - estimate.alpha0_rad  # north is -alpha0
    return out, estimates


def identify_north(time, observed, unknowns: int, **known) -> NorthEstimate:
    """The production estimator (:func:`~.estimate.identify`, keywords as there), quietly.

    Levenberg-Marquardt's trial steps may probe a decay rate at which the Bessel
    basis overflows; the fit rejects such steps, so numpy's floating-point warnings
    about them are silenced here, and an estimate that is not finite raises instead.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (alpha - alpha0, or alpha + c for ``reading="absolute"``).
    unknowns : {2, 3, 4, 5}
        Number of unknowns identified.
    **known
        The keywords of :func:`~.estimate.identify`, SI: ``decay_rate`` (1/s), ``hm`` (N m s),
        ``inertia`` (kg m^2), ``omega_h`` (rad/s), ``reading`` and ``method``.

    Returns
    -------
    NorthEstimate
        The identified north with its standard errors.

    Raises
    ------
    IdentificationError
        The record does not determine the unknowns, or the fit ends at values that
        are not finite.
    """
    with np.errstate(all="ignore"):
        estimate = identify(time, observed, unknowns, **known)
    if not (math.isfinite(estimate.alpha0_rad) and math.isfinite(estimate.misfit)):
        raise IdentificationError(f"the {unknowns}-unknown fit ended at values that are not finite")
    return estimate


def estimate_outputs(estimate: NorthEstimate) -> dict[str, float]:
    """The outputs an estimate gives (SI), NaN where it has no value (a standard error without residual dof).

    Parameters
    ----------
    estimate : NorthEstimate
        What the estimator identified from one record.

    Returns
    -------
    dict of str to float
        Output name of :data:`OUTPUTS` -> value, SI (rad, rad/s, 1/s, 1/s^2, N m s, N m, rad^2; counts
        and ``converged`` as plain numbers); those of the truth and the case (north error, predicted
        standard error, omega_h, samples) are not among them.
    """
    std = estimate.alpha0_rad_std
    return {
        "north_rad": -estimate.alpha0_rad,
        "north_std_rad": math.nan if std is None else std,
        "identified_alpha0_rad": estimate.alpha0_rad,
        "identified_alpha0_dot_rad_s": estimate.alpha0_dot,
        "identified_decay_rate": estimate.decay_rate,
        "identified_directive_coefficient": estimate.B,
        "identified_hm": estimate.Hm,
        "identified_torque": estimate.torque,
        "identified_offset_rad": estimate.offset_rad or 0.0,
        "misfit_rad2": estimate.misfit,
        "residual_rms_rad": math.sqrt(estimate.misfit / estimate.n_samples),
        "model_evaluations": float(estimate.nfev),
        "converged": float(estimate.converged),
    }


__all__ = ["FIDELITIES", "OUTPUTS", "PARAMETERS", "evaluate", "fit_bytes", "identify_north", "member_bytes",
           "omega_h_of", "record_window", "records", "sample_count", "truth_of"]
