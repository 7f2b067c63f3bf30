"""Gyro vertical with integral correction measuring velocity.

Source: Drozdovich, V. N., "On an inertial method of measuring velocities",
Izvestiya VUZ, Priborostroyeniye, no. 3, pp. 29-39, 1959
(:data:`schuler.references.DROZDOVICH_1959`); equation numbers are the paper's.

- :mod:`~schuler.gyro_vertical.trajectory`: the vehicle on a great circle of the
  rotating Earth, its Earth and transport rates, the accelerations (15)-(21).
- :mod:`~schuler.gyro_vertical.model`: the equations of the vertical (5)-(13) with
  the compensation torques (8), their linear error model and its simulation.
- :mod:`~schuler.gyro_vertical.quasi_steady`: the quasi-steady velocity error (29),
  the split Schuler modes (27), the initial-tilt error (22)/(23), and the spectral
  analysis and mode fit of simulations.
- :mod:`~schuler.gyro_vertical.friction`: Coulomb friction (30)-(32) with exact
  stick/slip switching.
- :mod:`~schuler.gyro_vertical.evaluation`: parameters, outputs, ``evaluate``.
- :mod:`~schuler.gyro_vertical.actions`: the ``friction`` command.
- :mod:`~schuler.gyro_vertical.reproduction`: the source's worked example and errata, ``report``.
- :mod:`~schuler.gyro_vertical.results`: the result types, ``figures`` and ``data_files``.
- :mod:`~schuler.gyro_vertical.api`: ``SYSTEM`` (``schuler vertical``).
"""
