"""Ground gyrocompass during natural rotor run-down (source 004, Fedorov, Kikot, Shtefan).

Modules:

* :mod:`.motion` -- eqs. (1)-(9): the Bessel-function solution for any initial
  angle and rate, a constant harmful torque, derivatives, and the numerical simulator;
* :mod:`.identification` -- north (and lambda, B, the torque) from the observed
  motion by variable-projection least squares, with standard errors;
* :mod:`.grid` -- the source's three-stage grid search (vectorised, and one ODE
  integration per cell as the source did);
* :mod:`.observations` -- sampling, noise, quantisation, CSV records;
* :mod:`.monte_carlo` -- accuracy against observation time, predicted and simulated;
* :mod:`.reproduction` -- the source's Tables 1-3 against the toolkit;
* :mod:`.plots`, :mod:`.api` -- figures, and ``SYSTEM`` for the CLI and the report.
"""

from schuler.ground_gyrocompass.identification import NorthEstimate, identify
from schuler.ground_gyrocompass.motion import closed_form, simulate

__all__ = ["NorthEstimate", "closed_form", "identify", "simulate"]
