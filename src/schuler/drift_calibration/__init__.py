"""Gyro drift calibration by alternating-sign torque pulses, with autonomous azimuth (``schuler calibrate``).

Source: "Measuring the drift rate of gyroscopic devices by alternating-sign
controlled precession" (:data:`schuler.references.PULSE_CALIBRATION`); equation
numbers (2)-(16) are the article's.

Frame: site ENU; platform X, Y, Z right-handed with Z up; azimuth A0 of the
platform Y axis, clockwise from north. omega_X0 = Omega cos(phi) sin(A0) is the
apparent drift (-Omega . e_X); the command-sensor angle is the platform's angle
relative to the base about +X; estimation errors are estimated - true.
Modules: ``pulses`` (shapes, symmetry), ``stabilizer`` (one cycle, exact
simulation and closed forms), ``procedure`` ((15)/(16), asin/atan2,
multi-position), ``plant`` (3-D first-principles plant), ``error_budget`` (the
documented budget), ``draws`` (the budget's errors drawn per member),
``evaluation`` (parameters, outputs, ``evaluate``), ``results`` (result type, figures),
``reproduction``, ``plots``, ``api`` (``SYSTEM``).
"""
