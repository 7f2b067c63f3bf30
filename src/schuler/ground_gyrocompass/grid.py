"""The source's identification: a grid search refined three times (the baseline).

Fedorov et al. (2020) compares the simulator with the model on every cell of a grid over the
unknowns (alpha0, alpha0_dot[, lambda[, H_m]]), picks the cell of least misfit
F = sum (model - simulator)^2, and refines twice around it with steps ten times
smaller (Tables 1-3). Two implementations:

* :func:`misfit_grid`, vectorised: for each (lambda, B) pair the closed-form basis
  is computed once, and the misfit of every (alpha0, alpha0_dot) cell follows from
  the Gram matrix of the basis as a quadratic form; linear parameters the source
  did not have (harmful torque, reading offset) are eliminated exactly by
  projection in each cell;
* :func:`misfit_cells_ode`, the source's procedure: one numerical integration of
  eqs. (1)-(2) per cell (the benchmark's baseline).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.ground_gyrocompass.motion import basis, simulate
from schuler.ground_gyrocompass.problem import (
    UNKNOWN_SETS,
    Fit,
    check_record,
    covariance,
    design,
    full_jacobian,
    parameter_order,
)

AXES = ("alpha0", "alpha0_dot", "decay_rate", "coefficient")

STEP_ALPHA0 = math.pi / 540.0  # the source's alpha0 unit and first step, rad
STEP_ALPHA0_DOT = 1e-4  # rad/s
MAX_AXIS_POINTS = 100_000
"""Most values of one grid axis (the source's boxes have a few tens; this bounds the misfit grid's memory)."""


def axis(start: float, stop: float, step: float) -> np.ndarray:
    """Grid values start, start + step, ..., stop (inclusive, rounded to whole steps).

    Parameters
    ----------
    start, stop : float
        First and last value, in the axis's SI unit (rad, rad/s, 1/s or 1/s^2).
    step : float
        Spacing, same unit (> 0).

    Returns
    -------
    ndarray
        The values, same unit.

    Raises
    ------
    InvalidParameter
        ``step`` not finite and > 0, ``start``/``stop`` not finite or ``stop`` below ``start``, or more than
        :data:`MAX_AXIS_POINTS` values.

    Examples
    --------
    >>> axis(0.0, 1.0, 0.25)
    array([0.  , 0.25, 0.5 , 0.75, 1.  ])
    """
    if not (math.isfinite(step) and step > 0):
        raise InvalidParameter("step", f"must be finite and > 0, got {step!r}")
    if not (math.isfinite(start) and math.isfinite(stop) and stop >= start):
        raise InvalidParameter("stop", f"must be finite and >= start ({start!r}), got {stop!r}")
    count = int(round((stop - start) / step)) + 1
    if count > MAX_AXIS_POINTS:
        raise InvalidParameter("step", f"{step!r} gives {count} values from {start!r} to {stop!r}; "
                                       f"at most {MAX_AXIS_POINTS} are allowed")
    return start + step * np.arange(count)


def _source_box(a0, a0d, lam=None, hm=None):
    """A stage box from the source's printed ranges: (start, stop, step) per axis."""
    box = {
        "alpha0": (a0[0] * STEP_ALPHA0, a0[1] * STEP_ALPHA0, a0[2] * STEP_ALPHA0),
        "alpha0_dot": tuple(v * 1e-4 for v in a0d),
    }
    if lam is not None:
        box["decay_rate"] = tuple(v * 1e-3 for v in lam)
    if hm is not None:
        box["hm"] = hm
    return box


SOURCE_STAGES = {
    # Fedorov et al. (2020), text after Table 1 (2 unknowns); alpha0 in pi/540, alpha0_dot in 1e-4 rad/s
    2: [
        _source_box((-9, 9, 1), (-6, 6, 1)),
        _source_box((3.0, 5.9, 0.1), (3.0, 5.9, 0.1)),
        _source_box((3.60, 3.79, 0.01), (4.00, 4.29, 0.01)),
    ],
    # Table 2 (3 unknowns); lambda in 1e-3 1/s
    3: [
        _source_box((-9, 9, 1), (-6, 6, 1), (1.0, 3.0, 0.1)),
        _source_box((3, 5, 0.1), (3, 5, 0.1), (2.1, 2.3, 0.01)),
        _source_box((3.6, 3.8, 0.01), (4.01, 4.20, 0.01), (2.131, 2.160, 0.001)),
    ],
    # Table 3 (4 unknowns); H_m in N m s. The third stage's H_m range is garbled in
    # the source ("(0,431;0,432 3)"): 0.4310..0.4330 is taken, step 1e-4 as printed.
    4: [
        _source_box((-9, 9, 1), (-6, 6, 1), (1.0, 3.0, 0.1), (0.34, 0.54, 0.01)),
        _source_box((3, 5, 0.1), (3, 5, 0.1), (2.1, 2.3, 0.01), (0.42, 0.44, 0.001)),
        _source_box((3.6, 3.8, 0.01), (4.01, 4.20, 0.01), (2.131, 2.160, 0.001), (0.4310, 0.4330, 0.0001)),
    ],
}
"""The source's printed search boxes, SI: axis -> (start, stop, step); ``hm`` in N m s."""


def source_boxes(unknowns: int, inertia: float, omega_h: float) -> list[dict]:
    """The source's stage boxes for 2, 3 or 4 unknowns, with H_m turned into B = H_m Omega_h / J.

    Parameters
    ----------
    unknowns : {2, 3, 4}
        Number of unknowns of the source's table (Tables 1-3).
    inertia : float
        Moment of inertia J of the sensitive element, kg m^2.
    omega_h : float
        Horizontal Earth rate Omega_h, rad/s.

    Returns
    -------
    list of dict
        One box per stage: axis name -> (start, stop, step), SI (``coefficient`` in 1/s^2).
    """
    boxes = []
    for box in SOURCE_STAGES[unknowns]:
        box = dict(box)
        if "hm" in box:
            box["coefficient"] = tuple(v * omega_h / inertia for v in box.pop("hm"))
        boxes.append(box)
    return boxes


def misfit_grid(time, observed, alpha0, alpha0_dot, decay_rate, coefficient, reading="relative", torque=False):
    """Misfit F = sum (observed - model)^2 on a full grid, vectorised (rad^2).

    Parameters
    ----------
    time, observed : ndarray (n,)
        Record: s, rad.
    alpha0, alpha0_dot, decay_rate, coefficient : ndarray
        Grid axes: rad, rad/s, 1/s, 1/s^2.
    reading : {"relative", "absolute"}
        With "absolute" the unknown offset is eliminated exactly in each cell.
    torque : bool
        Eliminate a constant harmful torque exactly in each cell (5 unknowns).

    Returns
    -------
    ndarray, shape (n_lambda, n_B, n_alpha0, n_alpha0_dot)

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> y = closed_form(t, 0.0215, 4e-4, 2.15e-3, 0.0136) - 0.0215
    >>> f = misfit_grid(t, y, np.array([0.0, 0.0215]), np.array([4e-4]), np.array([2.15e-3]), np.array([0.0136]))
    >>> f.shape, bool(f[0, 0, 1, 0] < 1e-20)
    ((1, 1, 2, 1), True)
    """
    time = np.asarray(time, dtype=float)
    observed = np.asarray(observed, dtype=float)
    lam = np.asarray(decay_rate, dtype=float)[:, None, None]
    b = np.asarray(coefficient, dtype=float)[None, :, None]
    u = basis(time[None, None, :], lam, b, torque=torque, derivatives=False).angle  # (3, nl, nb, n)
    first = u[0] - 1.0 if reading == "relative" else u[0]
    columns = np.stack([first, u[1]], axis=-1)  # (nl, nb, n, 2)
    y = np.broadcast_to(observed, first.shape)[..., None]
    extras = []
    if torque:
        extras.append(u[2])
    if reading == "absolute":
        extras.append(np.ones_like(first))
    if extras:
        # project out the linear parameters the grid does not scan (exact elimination)
        q, _ = np.linalg.qr(np.stack(extras, axis=-1))
        columns = columns - q @ (np.swapaxes(q, -1, -2) @ columns)
        y = y - q @ (np.swapaxes(q, -1, -2) @ y)
    gram = np.swapaxes(columns, -1, -2) @ columns  # (nl, nb, 2, 2)
    g = (np.swapaxes(columns, -1, -2) @ y)[..., 0]  # (nl, nb, 2)
    yy = (np.swapaxes(y, -1, -2) @ y)[..., 0, 0]
    a = np.asarray(alpha0, dtype=float)[:, None]
    v = np.asarray(alpha0_dot, dtype=float)[None, :]
    e = (..., None, None)
    # the quadratic form can dip below zero by round-off (~1e-17) at an exact fit
    return np.maximum(
        yy[e]
        - 2.0 * (a * g[..., 0][e] + v * g[..., 1][e])
        + a * a * gram[..., 0, 0][e]
        + 2.0 * a * v * gram[..., 0, 1][e]
        + v * v * gram[..., 1, 1][e],
        0.0,
    )


def misfit_cells_ode(time, observed, cells, reading="relative"):
    """The source's procedure: one numerical integration of eqs. (1)-(2) per grid cell.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate alpha - alpha0, rad.
    cells : ndarray (n_cells, 4)
        (alpha0 rad, alpha0_dot rad/s, lambda 1/s, B 1/s^2) per cell.
    reading : {"relative"}
        The source's observed coordinate alpha - alpha0.

    Returns
    -------
    ndarray (n_cells,)
        Misfit per cell, rad^2.
    """
    if reading != "relative":
        raise InvalidParameter("reading", "the source's procedure observes alpha - alpha0 (relative)")
    out = np.empty(len(cells))
    for k, (a0, a0d, lam, b) in enumerate(cells):
        model = simulate(time, a0, a0d, lam, b) - a0
        out[k] = np.sum((observed - model) ** 2)
    return out


@dataclass(frozen=True)
class Stage:
    """One grid stage: its axes, the best cell and its misfit.

    ``box`` maps each scanned axis to (start, stop, step) in SI (``coefficient``
    is B); ``best`` holds the best cell's values; ``misfit`` its F (rad^2);
    ``cells`` the number of cells; ``surface`` the misfit over (alpha0, alpha0_dot)
    at the best (lambda, B).
    """

    box: dict
    best: dict
    misfit: float
    cells: int
    surface: np.ndarray


def run_stage(time, observed, box, decay_rate, coefficient, reading="relative", torque=False) -> Stage:
    """Evaluate one stage box; axes missing from ``box`` are held at the known values.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (alpha - alpha0, or alpha + c with ``reading="absolute"``).
    box : dict of str to (float, float, float)
        Scanned axis -> (start, stop, step), SI: ``alpha0`` (rad) and ``alpha0_dot`` (rad/s) always,
        ``decay_rate`` (1/s) and ``coefficient`` (1/s^2) when scanned.
    decay_rate : float
        lambda, 1/s, when not scanned.
    coefficient : float
        B, 1/s^2, when not scanned.
    reading : {"relative", "absolute"}
        With "absolute" the unknown offset is eliminated exactly in each cell.
    torque : bool
        Eliminate a constant harmful torque exactly in each cell (5 unknowns).

    Returns
    -------
    Stage
        The best cell, its misfit (rad^2) and the misfit surface over (alpha0, alpha0_dot).
    """
    axes = {
        "alpha0": axis(*box["alpha0"]),
        "alpha0_dot": axis(*box["alpha0_dot"]),
        "decay_rate": axis(*box["decay_rate"]) if "decay_rate" in box else np.array([decay_rate]),
        "coefficient": axis(*box["coefficient"]) if "coefficient" in box else np.array([coefficient]),
    }
    grid = misfit_grid(
        time, observed, axes["alpha0"], axes["alpha0_dot"], axes["decay_rate"], axes["coefficient"], reading, torque
    )
    i_lam, i_b, i_a, i_v = np.unravel_index(int(np.argmin(grid)), grid.shape)
    best = {
        "alpha0": float(axes["alpha0"][i_a]),
        "alpha0_dot": float(axes["alpha0_dot"][i_v]),
        "decay_rate": float(axes["decay_rate"][i_lam]),
        "coefficient": float(axes["coefficient"][i_b]),
    }
    return Stage(dict(box), best, float(grid[i_lam, i_b, i_a, i_v]), grid.size, grid[i_lam, i_b])


def refine(time, observed, stages, decay_rate, coefficient, reading="relative", torque=False) -> list[Stage]:
    """Run a list of stage boxes in order (each is independent, as printed in the source).

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (alpha - alpha0, or alpha + c with ``reading="absolute"``).
    stages : list of dict
        The boxes (:func:`run_stage`; e.g. :func:`source_boxes`), SI.
    decay_rate : float
        lambda, 1/s, where not scanned.
    coefficient : float
        B, 1/s^2, where not scanned.
    reading : {"relative", "absolute"}
        With "absolute" the unknown offset is eliminated exactly in each cell.
    torque : bool
        Eliminate a constant harmful torque exactly in each cell.

    Returns
    -------
    list of Stage
        One per box, in order.
    """
    return [run_stage(time, observed, box, decay_rate, coefficient, reading, torque) for box in stages]


def first_box(unknowns: int, decay_rate: float, coefficient: float) -> dict:
    """The generic first stage: the source's spans around the nominal lambda and B.

    alpha0 over (-9..9) pi/540 in steps of pi/540, alpha0_dot over (-6..6)e-4 rad/s in
    steps of 1e-4 (the source's box); lambda over the nominal +-50 % and B over the
    nominal +-25 % (the source's spans), 21 values each.

    Parameters
    ----------
    unknowns : {2, 3, 4, 5}
        Number of unknowns: lambda is scanned from 3, B from 4.
    decay_rate : float
        Nominal lambda, 1/s (the box's centre).
    coefficient : float
        Nominal B, 1/s^2 (the box's centre).

    Returns
    -------
    dict of str to (float, float, float)
        Axis -> (start, stop, step), SI.
    """
    box = {"alpha0": (-9 * STEP_ALPHA0, 9 * STEP_ALPHA0, STEP_ALPHA0), "alpha0_dot": (-6e-4, 6e-4, 1e-4)}
    for name, centre, half_span in (("decay_rate", decay_rate, 0.5), ("coefficient", coefficient, 0.25)):
        if name in UNKNOWN_SETS[unknowns]:
            step = half_span * centre / 10
            box[name] = (centre - 10 * step, centre + 10 * step, step)
    return box


def refine_around(time, observed, box, decay_rate, coefficient, stages=3, reading="relative", torque=False):
    """Run ``box``, then re-centre on the best cell with steps ten times finer (+-10 steps).

    This is the source's procedure made automatic: each later box spans one
    previous step either side of the previous optimum.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (alpha - alpha0, or alpha + c with ``reading="absolute"``).
    box : dict of str to (float, float, float)
        The first stage's box, SI (:func:`first_box`).
    decay_rate : float
        lambda, 1/s, where not scanned.
    coefficient : float
        B, 1/s^2, where not scanned.
    stages : int
        Number of stages, the first included.
    reading : {"relative", "absolute"}
        With "absolute" the unknown offset is eliminated exactly in each cell.
    torque : bool
        Eliminate a constant harmful torque exactly in each cell.

    Returns
    -------
    list of Stage
        One per stage, in order.
    """
    results = [run_stage(time, observed, box, decay_rate, coefficient, reading, torque)]
    for _ in range(1, stages):
        best = results[-1].best
        box = {name: (best[name] - limits[2], best[name] + limits[2], limits[2] / 10) for name, limits in box.items()}
        results.append(run_stage(time, observed, box, decay_rate, coefficient, reading, torque))
    return results


def identify_grid(time, observed, unknowns, decay_rate, coefficient, reading="relative", stages=3) -> Fit:
    """The source's three-stage grid refinement as an estimator (``method="grid"``).

    Linear parameters beyond the source's (harmful torque for 5 unknowns, reading
    offset) are eliminated exactly in each cell. ``nfev`` counts grid cells.
    Standard errors are those of the Jacobian at the best cell.

    Parameters
    ----------
    time : ndarray (n,)
        Sample times since release, s.
    observed : ndarray (n,)
        Observed coordinate, rad (alpha - alpha0, or alpha + c with ``reading="absolute"``).
    unknowns : {2, 3, 4, 5}
        Number of unknowns (:data:`~.problem.UNKNOWN_SETS`).
    decay_rate : float
        lambda, 1/s: known (2 unknowns) or the first box's centre.
    coefficient : float
        B, 1/s^2: known (2, 3 unknowns) or the first box's centre.
    reading : {"relative", "absolute"}
        What ``observed`` holds.
    stages : int
        Number of grid stages.

    Returns
    -------
    Fit
        The best cell of the last stage, the linear extras at it, and the covariance from the Jacobian there.

    Raises
    ------
    InvalidParameter
        A bad record (:func:`~.problem.check_record`).
    IdentificationError
        The unknowns are not identifiable from the record (rank-deficient Jacobian).
    """
    time, observed = check_record(time, observed, unknowns, reading)
    torque = unknowns == 5
    results = refine_around(
        time, observed, first_box(unknowns, decay_rate, coefficient), decay_rate, coefficient, stages, reading, torque
    )
    best, cells = results[-1].best, sum(stage.cells for stage in results)
    # the linear extras at the best cell, solved exactly
    phi, _, _, names = design(time, best["decay_rate"], best["coefficient"], unknowns, reading, derivatives=False)
    values = {"specific_torque": 0.0, "offset": 0.0, **best}
    fixed = phi[:, :2] @ np.array([best["alpha0"], best["alpha0_dot"]])
    if phi.shape[1] > 2:
        extra = np.linalg.lstsq(phi[:, 2:], observed - fixed, rcond=None)[0]
        values.update(dict(zip(names[2:], extra)))
        fixed = fixed + phi[:, 2:] @ extra
    residual = observed - fixed
    cov = covariance(full_jacobian(time, values, unknowns, reading), residual, unknowns)
    message = f"{stages}-stage grid refinement, {cells} cells"
    order = parameter_order(unknowns, reading)
    return Fit(values, order, cov, float(residual @ residual), residual, cells, True, message)
