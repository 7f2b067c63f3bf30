"""The five systems, as the scenario runner, sweeps and report see them.

Each system subpackage defines ``SYSTEM`` (a :class:`System`) in its ``api``
module; :func:`get_system` imports it on demand so the CLI starts fast.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from schuler.exceptions import InvalidParameter
from schuler.params import Parameter, parse_parameters

SYSTEM_MODULES: dict[str, str] = {
    "errors": "schuler.navigation_errors.api",
    "vertical": "schuler.gyro_vertical.api",
    "calibrate": "schuler.drift_calibration.api",
    "align": "schuler.gyrocompassing.api",
    "north": "schuler.ground_gyrocompass.api",
}
"""CLI name of each system -> module holding its ``SYSTEM``."""


@dataclass(frozen=True)
class ReproductionRow:
    """One published number beside the toolkit's value."""

    quantity: str
    printed: float | str | None
    computed: float
    unit: str
    agrees: bool
    note: str = ""


@dataclass(frozen=True)
class FigureRef:
    """A figure file (relative to the report folder) and its caption."""

    path: str
    caption: str


@dataclass
class ReportSection:
    """What one system contributes to the HTML report."""

    system: str
    title: str
    source: str
    summary: str
    rows: list[ReproductionRow] = field(default_factory=list)
    figures: list[FigureRef] = field(default_factory=list)
    commands: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class System:
    """A system's entry points for scenarios, sweeps and the report.

    Attributes
    ----------
    name : str
        CLI name (``errors``, ``vertical``, ``calibrate``, ``align``, ``north``).
    title, source : str
        Human title and the source document it follows.
    parameters : tuple of Parameter
        Exactly the ``run`` command's options (names with underscores).
    run : callable
        ``run(**si_values) -> Result``: what ``schuler NAME run`` does.
    reproduce : callable
        ``reproduce() -> Result``: the source's published case.
    report : callable
        ``report(outdir: Path) -> ReportSection``: writes its figures into
        ``outdir`` and describes them (modest sizes: the whole report < 2 min).
    sweep : callable or None
        ``sweep(values: dict[str, ndarray]) -> dict[str, ndarray]``: vectorised
        evaluation of many cases at once; ``values`` holds every parameter in SI
        as an array of length n_cases (a parameter left unset arrives as NaN for
        numbers and None for text or choices), the result one array per output
        (length n_cases, SI, names with their unit where not SI-obvious).
    """

    name: str
    title: str
    source: str
    parameters: tuple[Parameter, ...]
    run: Callable
    reproduce: Callable
    report: Callable[[Path], ReportSection]
    sweep: Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]] | None = None

    def run_case(self, **si_values):
        """``run`` with every parameter not given set to its default (SI values in, Result out).

        Raises
        ------
        InvalidParameter
            For a name that is not one of the system's parameters.
        """
        names = {p.name for p in self.parameters}
        unknown = sorted(set(si_values) - names)
        if unknown:
            raise InvalidParameter(unknown[0], f"unknown parameter of {self.name}; allowed: {', '.join(sorted(names))}")
        values = parse_parameters(self.parameters, {})
        values.update(si_values)
        return self.run(**values)


def get_system(name: str) -> System:
    """The :class:`System` registered under ``name``."""
    if name not in SYSTEM_MODULES:
        raise InvalidParameter("system", f"{name!r} is not one of {', '.join(SYSTEM_MODULES)}")
    return importlib.import_module(SYSTEM_MODULES[name]).SYSTEM
