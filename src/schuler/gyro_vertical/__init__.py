"""Gyro vertical with integral correction measuring velocity (Drozdovich, 1959).

- :mod:`~schuler.gyro_vertical.trajectory`: the vehicle on a great circle of the
  rotating Earth, its Earth and transport rates, the accelerations (15)-(21).
- :mod:`~schuler.gyro_vertical.model`: the equations of the vertical (5)-(13) with
  the compensation torques (8), their linear error model and its simulation.
- :mod:`~schuler.gyro_vertical.quasi_steady`: the quasi-steady velocity error (29),
  the split Schuler modes (27), the initial-tilt error (22)/(23), and the spectral
  analysis and mode fit of simulations.
- :mod:`~schuler.gyro_vertical.friction`: Coulomb friction (30)-(32) with exact
  stick/slip switching.
- :mod:`~schuler.gyro_vertical.reproduction`: the source's worked example and errata.
- :mod:`~schuler.gyro_vertical.api`: ``run``, ``reproduce``, ``report``, ``sweep``, ``SYSTEM``.
"""
