"""The mission study: an inertial system's life, calibrate -> align -> navigate, and its error budget.

Conventions: NED navigation frame, body x forward / y right / z down, errors =
computed - true, sensor bias = measured - true, SI inside.

- :mod:`~schuler.mission.setup`  the instrument (``imu``: a grade, spec file or recording), calibration, alignment,
  trajectory, sources;
- :mod:`~schuler.mission.stages`  the alignment's residuals as a linear map of the sources;
- :mod:`~schuler.mission.coefficients`  the trajectory's kinematics averaged over each step;
- :mod:`~schuler.mission.covariance`  the budget on the WGS-84 psi-angle model, source by source;
- :mod:`~schuler.mission.monte_carlo`  the nonlinear INS over members drawn from the same sources;
- :mod:`~schuler.mission.aiding`  with GNSS aiding through outages (and on the drive zero-velocity stops, odometer and
  non-holonomic constraint, :mod:`~schuler.mission.aiding_measurements`): every source through the aided filter's
  closed loop; :mod:`~schuler.mission.aided_monte_carlo` ``schuler aided``'s filter on the nonlinear INS over the
  members;
  :mod:`~schuler.mission.survival` the longest outage within a bound, from a sweep;
- :mod:`~schuler.mission.evaluation`, :mod:`~schuler.mission.results`, :mod:`~schuler.mission.plots`,
  :mod:`~schuler.mission.reproduction`, :mod:`~schuler.mission.api`  the system on the contract.
"""
