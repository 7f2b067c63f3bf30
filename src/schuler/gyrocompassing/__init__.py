"""Physical gyrocompassing of a semi-analytic platform INS (source 003, KPI lab manual).

Before navigating, a platform INS is levelled and then turned to north: in
physical gyrocompassing the accelerometers sense the apparent drift of a platform
axis that is off the horizontal Earth rate U_eta and drive the platform in the
level and azimuth channels.

- :mod:`~schuler.gyrocompassing.models`: the linear models (1.17) corrected, (1.18), (1.19) on the exact engine;
- :mod:`~schuler.gyrocompassing.analytic`: steady state (1.21)/(1.25), transient (1.22)/(1.24), settling time, design;
- :mod:`~schuler.gyrocompassing.study`: the lab's tasks in one namespace over
  :mod:`~schuler.gyrocompassing.case` (cases, validation, gains, closed forms of many cases),
  :mod:`~schuler.gyrocompassing.simulation` (runs with constraint checks, batched simulation) and
  :mod:`~schuler.gyrocompassing.monte_carlo`;
- :mod:`~schuler.gyrocompassing.reproduction`: the source's design example and errata;
- :mod:`~schuler.gyrocompassing.api`: ``SYSTEM`` for the CLI (``schuler align``), scenarios, sweeps and report.
"""
