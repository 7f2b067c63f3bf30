"""Physical gyrocompassing of a semi-analytic platform INS (Meleshko, KPI lab manual; equations (1.x) are its).

Before navigating, a platform INS is levelled and then turned to north: in
physical gyrocompassing the accelerometers sense the apparent drift of a platform
axis that is off the horizontal Earth rate U_eta and drive the platform in the
level and azimuth channels.

- :mod:`~schuler.gyrocompassing.models`: the linear models (1.17) corrected, (1.18), (1.19) on the exact engine;
- :mod:`~schuler.gyrocompassing.analytic`: steady state (1.21)/(1.25), transient (1.22)/(1.24), settling time;
  the design T, zeta <-> c_Gamma, c_a (end of Sec. 2) is the core's :mod:`schuler.core.gyrocompass_design`;
- :mod:`~schuler.gyrocompassing.case`: cases, validation, gains, closed forms of many cases at once;
- :mod:`~schuler.gyrocompassing.simulation`: runs with the task-1 constraint checks, batched simulation;
- :mod:`~schuler.gyrocompassing.evaluation`: the system's parameters, outputs and ``evaluate`` (a run in full)
  (Monte Carlo members draw the residual drifts and accelerometer biases);
- :mod:`~schuler.gyrocompassing.results`: how a run renders, its figures and data files;
- :mod:`~schuler.gyrocompassing.reproduction`: the source's design example and errata, the report section;
- :mod:`~schuler.gyrocompassing.api`: ``SYSTEM`` for the CLI (``schuler align``), scenarios, sweeps and report.
"""
