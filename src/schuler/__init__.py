"""schuler: model, simulate and analyse gyroscopic navigation instruments.

Five instrument systems, one subpackage each:

- :mod:`schuler.navigation_errors`  Schuler-tuned INS error propagation (Bollay).
- :mod:`schuler.gyro_vertical`      gyro vertical with integral correction (Drozdovich).
- :mod:`schuler.drift_calibration`  gyro drift calibration by alternating torque pulses.
- :mod:`schuler.gyrocompassing`     physical gyrocompassing of a platform INS.
- :mod:`schuler.ground_gyrocompass` ground gyrocompass during rotor run-down.

The shared numerical core (Earth constants, the exact linear-systems engine,
streaming statistics) is :mod:`schuler.core`; it works in SI units only.
Unit parsing lives at the boundary in :mod:`schuler.units`.
"""

__version__ = "0.1.0"
