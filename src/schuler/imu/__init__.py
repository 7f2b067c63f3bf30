"""The IMU layer: recordings, sensor error models from spec sheets, Allan variance, inputs for the other systems.

The everyday functions, with options as Python values (SI numbers, unit text or pint units, names):

- :func:`read_record` (path, ...) -> :class:`~schuler.imu.record.ImuRecord`: any IMU file in memory, rates in
  SI (rad/s, m/s^2), body axes x forward, y right, z down;
- :func:`allan_deviation` (record or path, channels=None, ...) -> :class:`~schuler.imu.results.AllanResult`:
  overlapping Allan deviation (rad/s, m/s^2) over tau (s) with 68 % bounds, the IEEE 952 terms and the grade;
  ``to_dataframe()`` indexed by ``tau_s``, ``plot()``;
- :func:`identify` (record or path, channels=None, ...) -> :class:`~schuler.imu.results.IdentifiedTerms`:
  N, B, K, Q, R per channel in SI with uncertainties and resolvability.

>>> import schuler.imu
>>> schuler.imu.__all__
['allan_deviation', 'identify', 'read_record']

The modules:

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
- :mod:`~schuler.imu.noise_terms`: IEEE 952 terms by weighted least squares, uncertainties, resolvability;
- :mod:`~schuler.imu.characterise`: six-channel analysis, grade, round trip, the PSINS reproduction;
- :mod:`~schuler.imu.system_inputs`: error model -> parameters of align, calibrate, north, errors, vertical;
- :mod:`~schuler.imu.analysis`: the everyday functions above;
- :mod:`~schuler.imu.results`, :mod:`~schuler.imu.plots`: typed results, figures and the system's files;
- :mod:`~schuler.imu.static`: latitude and attitude of a record at rest from its mean rates;
- :mod:`~schuler.imu._kernels`: the numba time loops.

The system on the contract (``schuler imu``):

- :mod:`~schuler.imu.api`: ``SYSTEM``;
- :mod:`~schuler.imu.evaluation`: parameters, outputs and ``evaluate`` (a run in full with its Allan curves);
- :mod:`~schuler.imu.actions`: ``info``, ``allan`` and ``simulate``;
- :mod:`~schuler.imu.run_results`: how a run renders, what ``simulate`` returns;
- :mod:`~schuler.imu.reproduction`: the grade figures round-tripped and the PSINS recording, the report section;
- :mod:`~schuler.imu.instrument`: ``--imu`` on align, calibrate, north, errors and vertical (and ``[instrument]``).
"""

from schuler.imu.analysis import allan_deviation, identify, read_record

__all__ = ["allan_deviation", "identify", "read_record"]
