"""Studies over the five systems: scenario files, sweeps and the HTML report.

- :mod:`schuler.study.scenario`  TOML scenario files, validated against each system's parameters.
- :mod:`schuler.study.sweep`     grids and Monte Carlo in vectorised, resumable chunks on
  in-process, local-process or Dask executors.
- :mod:`schuler.study.report`    the self-contained HTML report (``schuler report``).
- :mod:`schuler.study.plots`     summary plots of a sweep.
"""
