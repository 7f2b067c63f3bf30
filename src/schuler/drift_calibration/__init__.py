"""System 3: gyro drift calibration by alternating-sign torque pulses, with autonomous azimuth (source 001).

Frame: site ENU; platform X, Y, Z right-handed with Z up; azimuth A0 of the
platform Y axis, clockwise from north. omega_X0 = Omega cos(phi) sin(A0) is the
apparent drift (-Omega . e_X); the command-sensor angle is the platform's angle
relative to the base about +X. Modules: ``pulses`` (shapes, symmetry),
``stabilizer`` (one cycle, exact simulation and closed forms), ``procedure``
((15)/(16), asin/atan2, multi-position), ``plant`` (3-D first-principles plant),
``error_budget`` (the budget), ``monte_carlo`` (the procedure over the budget),
``reproduction``, ``plots``, ``api``.
"""
