"""The IMU layer: recordings, sensor error models from spec sheets, Allan variance, inputs for the other systems.

Body frame x forward, y right, z down; NED navigation frame; sensor bias =
measured - true; everything SI inside (rad, rad/s, m/s^2, rad/sqrt(s) ...),
spec-sheet units (deg/sqrt(h), ug/sqrt(Hz), ppm ...) only at the boundary
through :mod:`schuler.units`.

- :mod:`~schuler.imu.record`: :class:`ImuRecord` (rates or increments), axis conversions, :func:`record_info`;
- :mod:`~schuler.imu.readers`: the project's CSV (with a column/unit mapping) and PSINS ``.imu``; located errors;
- :mod:`~schuler.imu.native`: the Parquet format, chunked writer and reader;
- :mod:`~schuler.imu.files`: :func:`open_record`, :func:`read_record`, :func:`write_record` by suffix;
- :mod:`~schuler.imu.error_model`: per-axis error terms, Gauss-Markov and flicker, their Allan variance (IEEE 952);
- :mod:`~schuler.imu.spec`: TOML spec files and the grade presets with their sources;
- :mod:`~schuler.imu.simulate`: N members x T samples, windowed, seeded, independent of the cut;
- :mod:`~schuler.imu.allan`: streaming overlapping Allan deviation with confidence intervals;
- :mod:`~schuler.imu.identify`: IEEE 952 terms by weighted least squares, uncertainties, resolvability;
- :mod:`~schuler.imu.characterise`: six-channel analysis, grade, round trip, the PSINS reproduction;
- :mod:`~schuler.imu.system_inputs`: error model -> parameters of align, calibrate, north, errors;
- :mod:`~schuler.imu.results`, :mod:`~schuler.imu.plots`: typed results and figures;
- :mod:`~schuler.imu.static`: latitude and attitude of a record at rest from its mean rates;
- :mod:`~schuler.imu._kernels`: the numba time loops.

The system on the contract (``schuler imu``):

- :mod:`~schuler.imu.api`: ``SYSTEM``;
- :mod:`~schuler.imu.evaluation`: parameters, outputs, ``evaluate`` and ``run_case``;
- :mod:`~schuler.imu.actions`: ``info``, ``allan`` and ``simulate``;
- :mod:`~schuler.imu.run_results`: what ``run`` and ``simulate`` return and write;
- :mod:`~schuler.imu.reproduction`: the grade figures round-tripped and the PSINS recording, the report section;
- :mod:`~schuler.imu.instrument`: ``--imu`` on align, calibrate, north and errors (and ``[instrument]``).
"""
