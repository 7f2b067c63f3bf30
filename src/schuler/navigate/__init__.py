"""The nonlinear INS on WGS-84: the truth, strapdown and platform mechanizations, and the seeds' referee.

Every model elsewhere in schuler is linear; this package simulates the inertial
navigator itself, without linearisation, on the WGS-84 ellipsoid, so that the
linear models can be held against it. Conventions (spec 06): NED navigation
frame, body x forward / y right / z down, aerospace roll/pitch/heading, errors =
computed - true, sensor bias = measured - true, SI throughout.

Modules, from the vehicle to the verdicts:

- :mod:`~schuler.navigate.trajectory`  stationary, great circle (geodesic) and C^2 waypoint profiles;
- :mod:`~schuler.navigate.profile`  the waypoint profiles' TOML format and its validation;
- :mod:`~schuler.navigate.truth`  the truth and the ideal IMU by inverse mechanization, streamed;
- :mod:`~schuler.navigate.errors`  initial errors, constant sensor errors per member, the noise interface;
- :mod:`~schuler.navigate.mechanization`  :func:`navigate`: strapdown (Groves 2013 eqs. (2.123),
  (5.44), (5.54), (5.56), (5.73), (5.77), (5.86); Savage 2000 coning and sculling) or platform, vertical
  channel free / held / baro-aided, batches of members, errors at the output step;
- :mod:`~schuler.navigate.alignment`  the KPI platform under the gyrocompassing control law (1.6),
  nonlinear, and its comparison with (1.17) and (1.19);
- :mod:`~schuler.navigate.linear`  the WGS-84 psi-angle model (:mod:`schuler.navigation_errors.three_d`)
  along a run, in the run's own variables: first-order agreement;
- :mod:`~schuler.navigate.seeds`  Bollay's five error sources and Drozdovich's worked example against
  the nonlinear INS;
- :mod:`~schuler.core.attitude`  Euler angles, quaternions, rotation vectors;
- :mod:`~schuler.navigate.results`, :mod:`~schuler.navigate.plots`  typed results and figures.

The time loops are numba kernels in the private ``_kernels``, ``_loops`` and
``_alignment_kernel`` modules.
"""
