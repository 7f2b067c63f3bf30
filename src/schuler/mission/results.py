"""What ``schuler mission run`` returns: :class:`MissionResult`, the one result rendered as a budget."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from schuler.results import SystemResult
from schuler.units import to_unit


@dataclass(kw_only=True)
class MissionResult(SystemResult):
    """One mission: the covariance analysis's final 1-sigma errors and the error budget (SI).

    The outputs (``position_error_sigma_m`` ...) read as attributes; the extras
    ``budget`` (every source's share of the final horizontal position-error
    variance, the shares sum to 1), ``dominant_source`` and ``instrument`` too;
    ``histories["mission_budget"]`` holds the 1-sigma errors and every source's
    variance at every output step (``mission_budget.csv``). The top-level
    1-sigma values are the covariance at the nominal case. With a Monte Carlo,
    ``to_dict()["monte_carlo"]`` also holds the comparison of like with like, in m:

    * ``position_error_sigma_m``: the root mean square of the members' final
      horizontal position errors (nonlinear INS);
    * ``position_error_sigma_standard_error_m``: its sampling standard error,
      std(e^2) / (2 RMS sqrt(N)) over the members kept (the delta method);
    * ``covariance_position_error_sigma_m``: the covariance over the members'
      own cases, sqrt(mean of their 1-sigma^2), what the RMS estimates when the
      members draw scenario values (a ``[monte_carlo]`` table); without draws it
      is the nominal one;
    * ``nominal_covariance_position_error_sigma_m``: the covariance at the
      nominal case (the top-level ``position_error_sigma_m``).

    With aiding, ``outages`` lists each outage's ``start_s``, ``duration_s``,
    ``horizontal_error_sigma_m`` (covariance, at its end) and ``shares``, and
    ``monte_carlo.outages`` the members' ``horizontal_error_end_rms_m`` (RMS of
    their horizontal errors at its end) and ``horizontal_error_max_rms_m`` (RMS
    of each member's largest inside it) beside that 1-sigma, for the first
    :data:`~schuler.mission.aided_monte_carlo.OUTAGE_SLOTS` outages.
    """

    def to_dict(self) -> dict[str, Any]:
        data = super().to_dict()
        if self.monte_carlo is not None and isinstance(data.get("monte_carlo"), dict):
            data["monte_carlo"].update(self.comparison())
            if self.extras.get("outages"):
                data["monte_carlo"]["outages"] = self.outage_comparison()
        return data

    def outage_comparison(self) -> list[dict[str, float | None]]:
        """Per outage: the members' RMS horizontal errors at its end and of their largest in it, m.

        Returns
        -------
        list of dict
            ``start_s``, ``duration_s`` (s), ``horizontal_error_end_rms_m``, ``horizontal_error_max_rms_m`` (the
            Monte Carlo's, None where no member has a value) and ``horizontal_error_sigma_m`` (the covariance's),
            m; empty without a Monte Carlo or outages.
        """
        if self.monte_carlo is None:
            return []
        statistics = self.monte_carlo.statistics
        out = []
        for k, outage in enumerate(self.extras.get("outages", ()), start=1):
            names = {kind: f"member_outage_{k}_horizontal_error_{kind}_m" for kind in ("end", "max")}
            if names["end"] not in statistics:
                break
            out.append({"start_s": outage["start_s"], "duration_s": outage["duration_s"],
                        "horizontal_error_end_rms_m": statistics[names["end"]].rms,
                        "horizontal_error_max_rms_m": statistics[names["max"]].rms,
                        "horizontal_error_sigma_m": outage["horizontal_error_sigma_m"]})
        return out

    def comparison(self) -> dict[str, float]:
        """The covariance beside the Monte Carlo over the same members, m (empty without a Monte Carlo).

        Returns
        -------
        dict of str to float
            ``position_error_sigma_m`` (the members' RMS, nonlinear INS), its sampling
            ``position_error_sigma_standard_error_m``, ``covariance_position_error_sigma_m`` (over the members'
            cases) and ``nominal_covariance_position_error_sigma_m`` (at the nominal case), m.
        """
        if self.monte_carlo is None:
            return {}
        statistics = self.monte_carlo.statistics

        def rms(name: str) -> float:  # None when no member has a finite value
            value = statistics[name]["rms"]
            return math.nan if value is None else float(value)

        kept = np.asarray(self.monte_carlo.samples.get("member_position_error_m", ()), dtype=float)
        kept = kept[np.isfinite(kept)]
        squares = kept**2
        standard_error = (float(np.std(squares, ddof=1) / (2.0 * math.sqrt(np.mean(squares)) * math.sqrt(kept.size)))
                          if kept.size > 1 and np.mean(squares) > 0 else math.nan)
        return {"position_error_sigma_m": rms("member_position_error_m"),
                "position_error_sigma_standard_error_m": standard_error,
                "covariance_position_error_sigma_m": rms("position_error_sigma_m"),
                "nominal_covariance_position_error_sigma_m": self.position_error_sigma_m}

    def render(self):
        from rich.console import Group
        from rich.table import Table

        table = Table(title=f"Mission error budget ({self.instrument})", show_header=True)
        table.add_column("quantity")
        table.add_column("value", justify="right")
        rows = [
            ("horizontal position error, 1-sigma (covariance at the nominal case)",
             f"{self.position_error_sigma_m:,.4g} m"),
            ("  north, east", f"{self.position_error_north_sigma_m:,.4g} m, {self.position_error_east_sigma_m:,.4g} m"),
            ("horizontal velocity error, 1-sigma", f"{self.velocity_error_sigma_m_s:.4g} m/s"),
            ("heading error, 1-sigma: after alignment, at the end",
             f"{to_unit(self.initial_heading_error_sigma_rad, 'arcmin'):.4g} arcmin, "
             f"{to_unit(self.heading_error_sigma_rad, 'arcmin'):.4g} arcmin"),
            ("tilt after alignment, 1-sigma", f"{to_unit(self.initial_tilt_sigma_rad, 'arcsec'):.4g} arcsec"),
            ("dominant source", f"{self.dominant_source} ({100 * self.dominant_share:.1f} %)"),
        ]
        if self.monte_carlo is not None:
            # like with like, below the nominal case: the covariance over the members' own cases beside their RMS
            compared = self.comparison()
            rows[2:2] = [("  covariance over the Monte Carlo members' cases (RMS of their 1-sigma)",
                          f"{compared['covariance_position_error_sigma_m']:,.4g} m"),
                         (f"  Monte Carlo ({self.monte_carlo.members} members, nonlinear INS): RMS, "
                          "its sampling 1-sigma",
                          f"{compared['position_error_sigma_m']:,.4g} m, "
                          f"{compared['position_error_sigma_standard_error_m']:,.2g} m")]
        for name, value in rows:
            table.add_row(name, value)
        shares = Table(title="Share of the final horizontal position-error variance", show_header=True)
        shares.add_column("source")
        shares.add_column("share", justify="right")
        for name, share in sorted(self.budget.items(), key=lambda item: -item[1]):
            if share >= 1e-4:
                shares.add_row(name, f"{100 * share:.2f} %")
        if not self.extras.get("outages"):
            return Group(table, shares)
        return Group(table, shares, self._outage_table())

    def _outage_table(self):
        from rich.table import Table

        compared = {(o["start_s"], o["duration_s"]): o for o in self.outage_comparison()}
        table = Table(title="GNSS outages: horizontal position error at the end", show_header=True)
        for name in ("start", "duration", "1-sigma (covariance)", "largest shares"):
            table.add_column(name, justify="left" if name == "largest shares" else "right")
        if compared:
            table.add_column("Monte Carlo RMS: end, largest", justify="right")
        for outage in self.extras["outages"]:
            top = sorted(outage["shares"].items(), key=lambda item: -item[1])[:3]
            row = [f"{outage['start_s']:g} s", f"{outage['duration_s']:g} s",
                   f"{outage['horizontal_error_sigma_m']:,.4g} m",
                   ", ".join(f"{name} {100 * share:.1f} %" for name, share in top)]
            if compared:
                mc = compared.get((outage["start_s"], outage["duration_s"]))
                row.append("" if mc is None or mc["horizontal_error_end_rms_m"] is None else
                           f"{mc['horizontal_error_end_rms_m']:,.4g} m, {mc['horizontal_error_max_rms_m']:,.4g} m")
            table.add_row(*row)
        return table

