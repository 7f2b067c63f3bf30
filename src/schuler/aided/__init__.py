"""Aided navigation: the INS corrected by external measurements in an error-state Kalman filter (spec 07).

The filter:

- :mod:`~schuler.aided.error_state`  the 15- or 21-state error model, its sensor-error processes, the filter's
  IMU model from the IMU layer's error model, and the exact discretisation;
- :mod:`~schuler.aided.measurements`  GNSS position and velocity at a lever arm: residuals and H;
- :mod:`~schuler.aided.kalman`  predict and the gated Joseph-form update on a batch of members;
- :mod:`~schuler.aided.ekf`  the closed-loop filter around :mod:`schuler.navigate`'s strapdown step;
- :mod:`~schuler.aided.analysis`  errors against a truth, drift through outages, NEES consistency.

The data it reads:

- :mod:`~schuler.aided.kfgins`  KF-GINS's text formats (IMU increments, GNSS with 7 or 13 columns, reference and
  result navigation) read and written in SI, with their bad-input checks;
- :mod:`~schuler.aided.kfgins_configuration`  KF-GINS's YAML configuration read as it is, into SI;
- :mod:`~schuler.aided.gnss`  GNSS epochs: the typed record, its simulation from a truth (noise, lever arm,
  latency), outages scheduled or detected;
- :mod:`~schuler.aided.epochs`  the truth at any times between IMU samples, and the simulated odometer and
  barometer;
- :mod:`~schuler.aided.files`  a run on files: the recording, GNSS, reference and configuration read and checked,
  KF-GINS's filter model and start.

The system (``schuler aided``): :mod:`~schuler.aided.evaluation` (parameters, outputs, ``evaluate``),
:mod:`~schuler.aided.outputs` (the result with its navigation, ``navigation.nav`` and ``navigation.csv``),
:mod:`~schuler.aided.plots`, :mod:`~schuler.aided.reproduction`, :mod:`~schuler.aided.api`.
"""
