"""North as users see it: the dispatcher :func:`identify` over both methods, and its result.

:func:`identify` turns the instrument's known or nominal values into the
problem's (B = H_m Omega_h / J, Fedorov et al. (2020), eq. (3)), runs one method, the
variable-projection least squares of :mod:`.varpro` (``method="lsq"``) or the
source's three-stage grid of :mod:`.grid` (``method="grid"``), and returns a
:class:`NorthEstimate` with standard errors.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.ground_gyrocompass.grid import identify_grid
from schuler.ground_gyrocompass.motion import check_decay_rate, directive_coefficient
from schuler.ground_gyrocompass.problem import Fit
from schuler.ground_gyrocompass.varpro import fit_least_squares
from schuler.results import Result


def dms_text(angle_deg: float) -> str:
    """An angle as signed degrees, minutes and seconds to 0.01 arcsec (``-1°13′48.00″``).

    Parameters
    ----------
    angle_deg : float
        The angle, deg.
    """
    sign = "-" if angle_deg < 0 else "+"
    seconds = round(abs(angle_deg) * 3600.0, 2)
    degrees, rest = divmod(seconds, 3600.0)
    minutes, seconds = divmod(rest, 60.0)
    return f"{sign}{int(degrees)}°{int(minutes):02d}′{seconds:05.2f}″"


@dataclass
class NorthEstimate(Result):
    """Identified north and run-down parameters, with standard errors (SI unless named).

    ``north_rad`` is the azimuth of north measured from the rotor axis at release,
    = -alpha0 (its degrees, minutes and seconds: ``north_dms``). JSON keys
    ``lambda``/``lambda_std`` hold ``decay_rate``.
    """

    unknowns: int
    method: str
    reading: str
    identified: list
    north_rad: float
    north_std_rad: float | None
    north_dms: str
    alpha0_rad: float
    alpha0_rad_std: float | None
    alpha0_dot: float
    alpha0_dot_std: float | None
    decay_rate: float
    decay_rate_std: float | None
    B: float
    B_std: float | None
    Hm: float
    Hm_std: float | None
    torque: float
    torque_std: float | None
    offset_rad: float | None
    offset_rad_std: float | None
    misfit: float
    residual_rms_rad: float
    n_samples: int
    nfev: int
    converged: bool
    message: str
    inertia: float
    omega_h: float
    correlation: dict
    time: np.ndarray = field(repr=False)
    observed: np.ndarray = field(repr=False)
    residuals: np.ndarray = field(repr=False)

    units: ClassVar[dict] = {
        "north_rad": "rad",
        "north_std_rad": "rad",
        "residual_rms_rad": "rad",
        "alpha0_dot": "rad/s",
        "alpha0_dot_std": "rad/s",
        "lambda": "1/s",
        "lambda_std": "1/s",
        "B": "1/s^2",
        "B_std": "1/s^2",
        "Hm": "N m s",
        "Hm_std": "N m s",
        "torque": "N m",
        "torque_std": "N m",
        "misfit": "rad^2",
        "inertia": "kg m^2",
        "omega_h": "rad/s",
    }
    json_names: ClassVar[dict] = {"decay_rate": "lambda", "decay_rate_std": "lambda_std"}

    def to_dict(self):
        data = super().to_dict()
        return {self.json_names.get(key, key): value for key, value in data.items()}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        std = None if self.north_std_rad is None else math.degrees(self.north_std_rad) * 3600.0  # shown, arcsec
        north_deg = math.degrees(self.north_rad)
        north = Table(title=f"North from the ground gyrocompass ({self.unknowns} unknowns, {self.method})")
        north.add_column("quantity")
        north.add_column("value", justify="right")
        north.add_column("standard error", justify="right")
        north.add_row("north from the rotor axis", f"{north_deg:.6f} deg", _std(std, 1 / 3600, "deg", ".2g"))
        north.add_row("", f"{north_deg * 60:.4f} arcmin", _std(std, 1 / 60, "arcmin", ".2g"))
        north.add_row("", f"{north_deg * 3600:.2f} arcsec", _std(std, 1.0, "arcsec", ".2g"))
        north.add_row("", self.north_dms, "")
        rows = [
            ("alpha0", self.alpha0_rad, self.alpha0_rad_std, "rad"),
            ("alpha0_dot", self.alpha0_dot, self.alpha0_dot_std, "rad/s"),
            ("lambda", self.decay_rate, self.decay_rate_std, "1/s"),
            ("B = Hm Omega_h / J", self.B, self.B_std, "1/s^2"),
            ("Hm", self.Hm, self.Hm_std, "N m s"),
            ("harmful torque", self.torque, self.torque_std, "N m"),
        ]
        if self.offset_rad is not None:
            rows.append(("reading offset", self.offset_rad, self.offset_rad_std, "rad"))
        params = Table(title="Parameters (known ones without standard error)")
        params.add_column("parameter")
        params.add_column("value", justify="right")
        params.add_column("standard error", justify="right")
        for name, value, error, unit in rows:
            params.add_row(name, f"{value:.10g} {unit}", "" if error is None else f"{error:.3g} {unit}")
        summary = (
            f"misfit {self.misfit:.4g} rad^2 over {self.n_samples} samples "
            f"(rms {math.degrees(self.residual_rms_rad) * 3600.0:.3g} arcsec), {self.nfev} model evaluations; "
            f"{self.message}"
        )
        return Group(north, params, summary)


def _std(std_arcsec, factor, unit, fmt):
    return "" if std_arcsec is None else f"{std_arcsec * factor:{fmt}} {unit}"


def make_estimate(fit: Fit, time, observed, unknowns, reading, method, inertia, omega_h) -> NorthEstimate:
    """Turn a :class:`Fit` into the user-facing :class:`NorthEstimate`.

    Parameters
    ----------
    fit : Fit
        The least-squares or grid result (SI).
    time : ndarray
        Sample times, s.
    observed : ndarray
        Observed coordinate, rad.
    unknowns : {2, 3, 4, 5}
    reading : {"relative", "absolute"}
    method : {"lsq", "grid"}
    inertia : float
        J, kg m^2.
    omega_h : float
        Omega_h, rad/s.
    """
    values = fit.values
    errors = {}
    correlation: dict[str, list[str] | np.ndarray | None] = {"parameters": list(fit.names), "matrix": None}
    if fit.covariance is not None:
        errors = dict(zip(fit.names, np.sqrt(np.diag(fit.covariance))))
        scale = np.sqrt(np.diag(fit.covariance))
        with np.errstate(invalid="ignore", divide="ignore"):
            matrix = fit.covariance / np.outer(scale, scale)
        correlation["matrix"] = np.where(np.isfinite(matrix), matrix, 0.0)

    def err(name, factor=1.0):
        if name not in fit.names or fit.covariance is None:
            return None
        return float(errors[name] * factor)

    hm_per_b = inertia / omega_h
    alpha0_std = err("alpha0")
    return NorthEstimate(
        unknowns=unknowns,
        method=method,
        reading=reading,
        identified=list(fit.names),
        north_rad=-values["alpha0"],
        north_std_rad=alpha0_std,
        north_dms=dms_text(math.degrees(-values["alpha0"])),
        alpha0_rad=values["alpha0"],
        alpha0_rad_std=alpha0_std,
        alpha0_dot=values["alpha0_dot"],
        alpha0_dot_std=err("alpha0_dot"),
        decay_rate=values["decay_rate"],
        decay_rate_std=err("decay_rate"),
        B=values["coefficient"],
        B_std=err("coefficient"),
        Hm=values["coefficient"] * hm_per_b,
        Hm_std=err("coefficient", hm_per_b),
        torque=values["specific_torque"] * inertia,
        torque_std=err("specific_torque", inertia),
        offset_rad=values["offset"] if reading == "absolute" else None,
        offset_rad_std=err("offset"),
        misfit=fit.misfit,
        residual_rms_rad=math.sqrt(fit.misfit / len(time)),
        n_samples=len(time),
        nfev=fit.nfev,
        converged=fit.converged,
        message=fit.message,
        inertia=inertia,
        omega_h=omega_h,
        correlation=correlation,
        time=np.asarray(time),
        observed=np.asarray(observed),
        residuals=fit.residuals,
    )


def identify(
    time, observed, unknowns: int = 4, *, decay_rate, hm, inertia, omega_h, reading="relative", method="lsq"
) -> NorthEstimate:
    """Identify north from an observed run-down record (Fedorov et al. (2020), eqs. (9)-(10)).

    Parameters
    ----------
    time : ndarray
        Sample times since release, s.
    observed : ndarray
        Observed coordinate, rad (alpha - alpha0 for ``reading="relative"``).
    unknowns : {2, 3, 4, 5}
        Parameters to identify (:data:`~.problem.UNKNOWN_SETS`).
    decay_rate : float
        lambda, 1/s: known (2 unknowns) or nominal start / grid centre.
    hm : float
        H_m, N m s: known (2, 3 unknowns) or nominal.
    inertia : float
        J, kg m^2 (known: only B = H_m Omega_h / J is identifiable).
    omega_h : float
        Omega_h, rad/s (known; e.g. from the latitude).
    reading : {"relative", "absolute"}
    method : {"lsq", "grid"}
        Variable-projection least squares (:func:`~.varpro.fit_least_squares`), or
        the source's three-stage grid refinement (:func:`~.grid.identify_grid`).

    Returns
    -------
    NorthEstimate

    Examples
    --------
    >>> from schuler.ground_gyrocompass.motion import closed_form
    >>> t = np.arange(0.0, 201.0)
    >>> b = 0.432 * 3.65e-5 / 1.1607e-3  # B = Hm Omega_h / J
    >>> y = closed_form(t, 0.0215, 4.08e-4, 2.15e-3, b) - 0.0215
    >>> est = identify(t, y, 2, decay_rate=2.15e-3, hm=0.432, inertia=1.1607e-3, omega_h=3.65e-5)
    >>> round(math.degrees(est.north_rad), 6), round(math.degrees(-0.0215), 6)
    (-1.231859, -1.231859)
    """
    coefficient = float(directive_coefficient(hm, omega_h, inertia))
    check_decay_rate(decay_rate)
    methods = {"lsq": fit_least_squares, "grid": identify_grid}
    if method not in methods:
        raise InvalidParameter("method", f"{method!r} is not one of {', '.join(methods)}")
    fit = methods[method](time, observed, unknowns, decay_rate, coefficient, reading)
    return make_estimate(fit, time, observed, unknowns, reading, method, inertia, omega_h)
