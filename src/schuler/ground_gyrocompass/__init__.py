"""Ground gyrocompass during natural rotor run-down (source 004, Fedorov, Kikot, Shtefan).

Modules:

* :mod:`.motion` -- eqs. (1)-(9): the Bessel-function solution for any initial
  angle and rate, a constant harmful torque, derivatives, and the numerical simulator;
* :mod:`.problem` -- the identification problem: unknown sets (2-5), record checks,
  the model's columns, the Jacobian and the covariance, shared by both methods;
* :mod:`.varpro` -- north (and lambda, B, the torque) by variable-projection least
  squares from a regression start, one record or many;
* :mod:`.grid` -- the source's three-stage grid search (vectorised, and one ODE
  integration per cell as the source did);
* :mod:`.estimate` -- :func:`identify`, the dispatcher over both methods, and the
  :class:`NorthEstimate` users see;
* :mod:`.observations` -- noise, quantisation, CSV records;
* :mod:`.monte_carlo` -- accuracy against observation time, predicted and simulated
  with the estimator users run;
* :mod:`.reproduction` -- the source's Tables 1-3 against the toolkit;
* :mod:`.plots`, :mod:`.api` -- figures, and ``SYSTEM`` for the CLI and the report.
"""

from schuler.ground_gyrocompass.estimate import NorthEstimate, identify
from schuler.ground_gyrocompass.motion import closed_form, simulate

__all__ = ["NorthEstimate", "closed_form", "identify", "simulate"]
