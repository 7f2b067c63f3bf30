"""Aided navigation: the INS corrected by external measurements (spec 07), and the data it reads.

- :mod:`~schuler.aided.kfgins`  KF-GINS's text formats (IMU increments, GNSS with 7 or 13 columns, reference and
  result navigation) read and written in SI, with their bad-input checks;
- :mod:`~schuler.aided.kfgins_configuration`  KF-GINS's YAML configuration read as it is, into SI;
- :mod:`~schuler.aided.gnss`  GNSS epochs: the typed record, its simulation from a truth (noise, lever arm,
  latency), outages scheduled or detected;
- :mod:`~schuler.aided.epochs`  the truth at any times between IMU samples, and the simulated odometer and
  barometer.
"""
