"""The source's machine experiment end to end: Tables 1-3 against the toolkit.

Source 004 integrates eqs. (1)-(2) with J = 1.1607e-3 kg m^2, Omega_h = 3.65e-5 1/s,
H_m = 0.432 N m s, lambda = 2.15e-3 1/s, alpha0 = 3.69 pi/540 rad,
alpha0_dot = 4.08e-4 1/s, samples every 1 s over 0..200 s, and identifies the
unknowns by a grid refined three times. Here the same record is made with the
numerical simulator, the printed stage boxes are re-run (vectorised closed form),
and the printed optima and misfits are compared with the computed ones. Table 1
(the whole first-stage misfit grid for two unknowns) is tested against several
readings of "misfit".
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from schuler.core.geometry import time_grid
from schuler.ground_gyrocompass import motion
from schuler.ground_gyrocompass.estimate import NorthEstimate, identify
from schuler.ground_gyrocompass.grid import STEP_ALPHA0, misfit_grid, refine, refine_around, source_boxes
from schuler.results import Footnotes, Result

K_VALUES = np.arange(-9, 10)  # alpha0 = k pi/540
M_VALUES = np.arange(-6, 7)  # alpha0_dot = m 1e-4 rad/s

TABLE_1 = 1e-3 * np.array(
    [
        [41.8, 41.6, 41.4, 41.2, 41.1, 40.9, 40.7, 40.6, 40.5, 40.3, 40.2, 40.1, 40.0],
        [38.7, 38.5, 38.3, 38.1, 37.9, 37.7, 37.6, 37.4, 37.3, 37.2, 37.0, 36.9, 36.8],
        [35.5, 35.3, 35.1, 34.9, 34.7, 34.6, 34.4, 34.3, 34.1, 34.0, 33.9, 33.8, 33.7],
        [32.4, 32.2, 32.0, 31.8, 31.6, 31.4, 31.2, 31.1, 30.9, 30.8, 30.7, 30.6, 30.5],
        [29.3, 29.1, 28.8, 28.6, 28.4, 25.1, 28.1, 27.9, 27.8, 27.6, 27.5, 27.4, 27.3],
        [26.2, 26.1, 25.7, 25.5, 25.3, 25.1, 24.9, 24.8, 24.6, 24.5, 24.3, 24.2, 24.1],
        [23.2, 22.9, 22.6, 22.4, 22.2, 22.0, 21.8, 21.6, 21.4, 21.3, 21.2, 21.1, 21.0],
        [20.1, 19.8, 19.5, 19.3, 19.0, 18.8, 18.6, 18.4, 18.3, 18.1, 18.0, 17.9, 17.8],
        [17.2, 16.8, 16.5, 16.2, 16.0, 15.7, 15.5, 15.3, 15.1, 15.0, 14.8, 14.7, 14.6],
        [14.3, 13.9, 13.5, 13.2, 12.9, 12.6, 12.4, 12.1, 12.0, 11.8, 11.7, 11.6, 11.5],
        [14.3, 11.1, 10.7, 10.3, 9.9, 9.6, 9.3, 9.0, 8.8, 8.6, 8.5, 8.4, 8.3],
        [9.3, 8.7, 8.2, 7.6, 7.1, 6.7, 6.3, 6.0, 5.7, 5.5, 5.3, 5.2, 5.2],
        [7.5, 6.9, 6.3, 5.6, 5.0, 4.4, 3.8, 3.2, 2.7, 2.4, 2.1, 2.1, 2.2],
        [5.9, 5.3, 4.7, 4.1, 3.5, 2.9, 2.3, 1.8, 1.3, 1.0, 0.9751, 1.2, 1.7],
        [6.3, 5.9, 5.5, 5.1, 4.8, 4.5, 4.3, 4.1, 4.0, 4.0, 4.1, 4.2, 4.5],
        [8.3, 8.1, 7.8, 7.6, 7.4, 7.3, 7.2, 7.1, 7.1, 7.2, 7.3, 7.4, 7.6],
        [10.9, 10.7, 10.6, 10.5, 10.4, 10.3, 10.3, 10.3, 10.3, 10.3, 10.4, 10.6, 10.7],
        [13.7, 13.6, 13.5, 13.4, 13.4, 13.4, 13.4, 13.4, 13.4, 13.5, 13.6, 13.7, 13.9],
        [16.7, 16.6, 16.5, 16.5, 16.5, 16.5, 16.5, 16.5, 16.6, 16.7, 16.8, 16.9, 17.0],
    ]
)
"""Source 004, Table 1: F(alpha0, alpha0_dot), rad^2; rows k = -9..9, columns m = -6..6."""

MISPRINTS = ((-5, -1), (1, -6))
"""Cells (k, m) of Table 1 that break their monotone rows: 25.1 between 28.4 and 28.1,
and 14.3 before 11.1, 10.7, ... in a decreasing row; left out of the comparisons."""

PRINTED_STAGES = {
    # unknowns: [(best alpha0 in pi/540, alpha0_dot in 1e-4, lambda in 1e-3, H_m), printed F (rad^2)]
    2: [((4, 4), 0.9751e-3), ((3.7, 4.1), 0.362e-4), ((3.69, 4.08), 0.0)],
    3: [((4, 4, 2.2), 0.9718e-3), ((3.7, 4.1, 2.14), 0.302e-4), ((3.69, 4.08, 2.150), 0.0)],
    4: [((4, 4, 2.2, 0.43), 0.974e-3), ((3.7, 4.1, 2.14, 0.432), 0.302e-4), ((3.69, 4.08, 2.150, 0.4320), 0.0)],
}
"""Source 004: text after Table 1, Table 2 and Table 3 (second-stage F is garbled in
Tables 2-3: 0.302e-4 / 0.262e-4 / 0.362e-4 all appear; 0.302e-4 is taken)."""

READINGS = {
    "sum of squares": lambda r: np.sum(r**2, axis=-1),
    "root of sum of squares": lambda r: np.sqrt(np.sum(r**2, axis=-1)),
    "mean square": lambda r: np.mean(r**2, axis=-1),
    "root mean square": lambda r: np.sqrt(np.mean(r**2, axis=-1)),
    "sum of |residual|": lambda r: np.sum(np.abs(r), axis=-1),
    "max |residual|": lambda r: np.max(np.abs(r), axis=-1),
}


def source_record():
    """The source's simulator output: times (s) and the observed alpha - alpha0 (rad)."""
    time = time_grid(motion.SOURCE_DURATION, motion.SOURCE_STEP)
    angle = motion.simulate(time, motion.SOURCE_ALPHA0, motion.SOURCE_ALPHA0_DOT, motion.SOURCE_LAMBDA, source_b())
    return time, angle - motion.SOURCE_ALPHA0


def source_b() -> float:
    """B of the source's experiment, 1/s^2."""
    return float(motion.directive_coefficient(motion.SOURCE_HM, motion.SOURCE_OMEGA_H, motion.SOURCE_INERTIA))


def _hm(b):
    return b * motion.SOURCE_INERTIA / motion.SOURCE_OMEGA_H


def _in_source_units(best: dict, unknowns: int) -> tuple:
    values = [best["alpha0"] / STEP_ALPHA0, best["alpha0_dot"] / 1e-4]
    if unknowns >= 3:
        values.append(best["decay_rate"] / 1e-3)
    if unknowns >= 4:
        values.append(_hm(best["coefficient"]))
    return tuple(round(v, 6) for v in values)


def stage_comparison(time, observed, unknowns: int) -> list[dict]:
    """Each printed stage of ``unknowns`` re-run: printed vs computed best cell and misfit."""
    stages = refine(
        time,
        observed,
        source_boxes(unknowns, motion.SOURCE_INERTIA, motion.SOURCE_OMEGA_H),
        motion.SOURCE_LAMBDA,
        source_b(),
    )
    rows = []
    for number, (stage, (printed_best, printed_f)) in enumerate(zip(stages, PRINTED_STAGES[unknowns]), start=1):
        computed = _in_source_units(stage.best, unknowns)
        names = [name for name in ("alpha0", "alpha0_dot", "decay_rate", "coefficient") if name in stage.box]
        steps = [stage.box[name][2] for name in names]
        scale = [STEP_ALPHA0, 1e-4, 1e-3, motion.SOURCE_OMEGA_H / motion.SOURCE_INERTIA][: len(steps)]
        same_cell = all(
            abs(p - c) * s < 0.5 * step for p, c, s, step in zip(printed_best, computed, scale, steps)
        )
        if printed_f == 0.0:
            misfit_agrees = stage.misfit < 1e-12
        else:
            misfit_agrees = abs(stage.misfit / printed_f - 1.0) < 0.05
        rows.append(
            {
                "unknowns": unknowns,
                "stage": number,
                "cells": stage.cells,
                "printed_best": list(printed_best),
                "computed_best": list(computed),
                "best_agrees": bool(same_cell),
                "printed_misfit": printed_f,
                "computed_misfit": stage.misfit,
                "misfit_agrees": bool(misfit_agrees),
            }
        )
    return rows


def honest_four_unknowns(time, observed) -> dict:
    """The 4-unknown first stage re-run, then refined around its real optimum.

    Returns the misfit at the printed best cell, the real best cell and misfit,
    and where the automatic refinement (+-1 previous step, steps / 10) ends.
    """
    box = source_boxes(4, motion.SOURCE_INERTIA, motion.SOURCE_OMEGA_H)[0]
    stages = refine_around(time, observed, box, motion.SOURCE_LAMBDA, source_b())
    printed = misfit_grid(
        time,
        observed,
        np.array([4 * STEP_ALPHA0]),
        np.array([4e-4]),
        np.array([2.2e-3]),
        np.array([0.43 * motion.SOURCE_OMEGA_H / motion.SOURCE_INERTIA]),
    ).item()
    final = stages[-1].best
    return {
        "printed_best_misfit": printed,
        "first_stage_best": list(_in_source_units(stages[0].best, 4)),
        "first_stage_misfit": stages[0].misfit,
        "refined_best": list(_in_source_units(final, 4)),
        "refined_misfit": stages[-1].misfit,
        "refined_alpha0_error_rad": final["alpha0"] - motion.SOURCE_ALPHA0,
    }


def table1_analysis(time, observed) -> dict:
    """Table 1 against readings of the misfit (relative and absolute coordinate).

    For each reading: the cell of its minimum, its value at the printed minimum cell
    (k = 4, m = 4), the single scale factor that best matches the table and the
    largest deviation left after it. A reading "reproduces" Table 1 if, after one
    scale factor, every cell agrees within 5 % (the table prints 2-3 digits).
    Also the fit of a quadratic form to the squared table (a norm of a residual
    linear in alpha0, alpha0_dot would fit exactly) and its shape against this
    experiment's.
    """
    b = source_b()
    u = motion.basis(time, motion.SOURCE_LAMBDA, b, torque=False, derivatives=False).angle
    alpha = observed + motion.SOURCE_ALPHA0
    a = (K_VALUES * STEP_ALPHA0)[:, None, None]
    v = (M_VALUES * 1e-4)[None, :, None]
    residuals = {
        "relative": a * (u[0] - 1.0) + v * u[1] - observed,
        "absolute": a * u[0] + v * u[1] - alpha,
    }
    keep = np.ones(TABLE_1.shape, dtype=bool)
    for k, m in MISPRINTS:
        keep[k + 9, m + 6] = False
    rows = []
    for coordinate, residual in residuals.items():
        for name, reading in READINGS.items():
            grid = reading(residual)
            k_min, m_min = np.unravel_index(int(np.argmin(grid)), grid.shape)
            log_ratio = np.log(grid[keep] / TABLE_1[keep])
            scale = float(np.exp(np.median(log_ratio)))
            deviation = float(np.max(np.abs(grid[keep] / (scale * TABLE_1[keep]) - 1.0)))
            rows.append(
                {
                    "coordinate": coordinate,
                    "reading": name,
                    "minimum_cell": [int(K_VALUES[k_min]), int(M_VALUES[m_min])],
                    "at_printed_minimum": float(grid[13, 10]),
                    "at_k0_m0": float(grid[9, 6]),
                    "best_scale": scale,
                    "max_deviation": deviation,
                    "reproduces": deviation < 0.05,
                }
            )
    # Table 1 squared against a general quadratic in (alpha0, alpha0_dot)
    da = (K_VALUES * STEP_ALPHA0 - motion.SOURCE_ALPHA0)[:, None] * np.ones((1, M_VALUES.size))
    dv = (M_VALUES * 1e-4 - motion.SOURCE_ALPHA0_DOT)[None, :] * np.ones((K_VALUES.size, 1))
    far = keep & (np.abs(K_VALUES - 4)[:, None] >= 3)  # away from the minimum, where rounding dominates
    x = np.column_stack([da[far] ** 2, da[far] * dv[far], dv[far] ** 2, da[far], dv[far], np.ones(far.sum())])
    coefficients = np.linalg.lstsq(x, TABLE_1[far] ** 2, rcond=None)[0]
    fitted = np.sqrt(np.clip(x @ coefficients, 0.0, None))
    shape = {}
    for coordinate, (w1, w2) in {"relative": (u[0] - 1.0, u[1]), "absolute": (u[0], u[1])}.items():
        shape[coordinate] = [float(2 * (w1 @ w2) / (w1 @ w1)), float((w2 @ w2) / (w1 @ w1))]
    simulated = residuals["relative"]
    return {
        "computed_sum_of_squares": np.sum(simulated**2, axis=-1),
        "readings": rows,
        "any_reading_reproduces": any(row["reproduces"] for row in rows),
        "quadratic_fit_max_deviation": float(np.max(np.abs(fitted / TABLE_1[far] - 1.0))),
        "table_shape": [float(coefficients[1] / coefficients[0]), float(coefficients[2] / coefficients[0])],
        "experiment_shape": shape,
    }


@dataclass
class SourceReproduction(Result):
    """The source's experiment reproduced: the fit of ``unknowns`` plus the grid tables.

    The estimate's keys (``alpha0_rad``, ``lambda``, ``Hm``, ``north_deg``, ``misfit``,
    ``nfev``, ``method`` and standard errors) sit at the top level of :meth:`to_dict`.
    """

    unknowns: int
    true_alpha0_rad: float
    alpha0_error_rad: float
    stages: list
    four_unknowns_first_stage: dict
    table1: dict
    estimate: NorthEstimate = field(repr=False, default=None)

    def to_dict(self):
        data = self.estimate.to_dict()
        data.update(super().to_dict())
        return data

    def render(self):
        from rich.console import Group
        from rich.table import Table

        stages = Table(title="Source 004, Tables 1-3: grid stages, printed vs computed (relative coordinate)")
        for column in ("unknowns", "stage", "cells", "printed best", "computed best", "printed F", "computed F", "note"):
            stages.add_column(column, justify="left" if column == "note" else "right")
        four = self.four_unknowns_first_stage
        misfit_note = (
            "erratum: the printed F is not the sum of squares of alpha - alpha0 that is minimised here; no reading "
            "of the misfit reproduces the source's Table 1 (see the table of readings below)"
        )
        first_stage_note = (
            f"erratum: the printed best (4, 4, 2.2, 0.43) is not the grid's minimum: F there is "
            f"{four['printed_best_misfit']:.4g}, the real best {tuple(four['first_stage_best'])} has "
            f"F = {four['first_stage_misfit']:.4g}; refining around it ends at {tuple(four['refined_best'])} "
            f"(alpha0 error {four['refined_alpha0_error_rad']:.3g} rad)"
        )
        # notes are long and some repeat: the table refers to them by number and lists each once below it
        footnotes = Footnotes()
        for row in self.stages:
            notes = []
            if not row["best_agrees"]:
                final = [r for r in self.stages if r["unknowns"] == row["unknowns"]][-1]
                notes.append(first_stage_note if (row["unknowns"], row["stage"]) == (4, 1) else (
                    "the printed cell is not the minimum of the sum of squares on this grid (the source minimises "
                    f"another misfit: see the note on F); the final stage {'agrees' if final['best_agrees'] else 'differs'}"
                ))
            if not row["misfit_agrees"]:
                notes.append(misfit_note)
            references = footnotes.reference(*notes)
            stages.add_row(
                str(row["unknowns"]),
                str(row["stage"]),
                str(row["cells"]),
                ", ".join(f"{v:g}" for v in row["printed_best"]),
                ", ".join(f"{v:g}" for v in row["computed_best"]) + ("" if row["best_agrees"] else " ✗"),
                f"{row['printed_misfit']:.4g}",
                f"{row['computed_misfit']:.4g}" + ("" if row["misfit_agrees"] else " ✗"),
                references,
            )
        readings = Table(title="Table 1 against readings of the misfit (none reproduces it within 5 %)")
        for column in ("coordinate", "reading", "min cell", "at (4, 4)", "scale", "max deviation"):
            readings.add_column(column, justify="right")
        for row in self.table1["readings"]:
            readings.add_row(
                row["coordinate"],
                row["reading"],
                str(tuple(row["minimum_cell"])),
                f"{row['at_printed_minimum']:.4g}",
                f"{row['best_scale']:.3g}",
                f"{100 * row['max_deviation']:.0f} %",
            )
        return Group(self.estimate.render(), stages, *footnotes.lines(), readings)


def reproduce(unknowns: int = 4, method: str = "lsq") -> SourceReproduction:
    """Reproduce the source's experiment and identify ``unknowns`` with ``method``.

    Examples
    --------
    >>> r = reproduce(2)
    >>> bool(abs(r.alpha0_error_rad) < 1e-9), r.stages[0]["computed_best"]
    (True, [4.0, 4.0])
    """
    time, observed = source_record()
    estimate = identify(
        time,
        observed,
        unknowns,
        decay_rate=motion.SOURCE_LAMBDA,
        hm=motion.SOURCE_HM,
        inertia=motion.SOURCE_INERTIA,
        omega_h=motion.SOURCE_OMEGA_H,
        method=method,
    )
    stages = [row for count in (2, 3, 4) for row in stage_comparison(time, observed, count)]
    analysis = table1_analysis(time, observed)
    return SourceReproduction(
        unknowns=unknowns,
        true_alpha0_rad=motion.SOURCE_ALPHA0,
        alpha0_error_rad=estimate.alpha0_rad - motion.SOURCE_ALPHA0,
        stages=stages,
        four_unknowns_first_stage=honest_four_unknowns(time, observed),
        table1=analysis,
        estimate=estimate,
    )
