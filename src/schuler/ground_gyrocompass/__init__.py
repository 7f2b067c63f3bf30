"""Ground gyrocompass during natural rotor run-down (Fedorov, Kikot, Shtefan (2020)).

Source: :data:`schuler.references.FEDOROV_2020`; equation numbers are the article's.

Modules:

* :mod:`~schuler.ground_gyrocompass.motion` -- eqs. (1)-(9): the Bessel-function solution for any initial
  angle and rate, a constant harmful torque, derivatives, and the numerical simulator;
* :mod:`~schuler.ground_gyrocompass.problem` -- the identification problem: unknown sets (2-5), record checks,
  the model's columns, the Jacobian and the covariance, shared by both methods;
* :mod:`~schuler.ground_gyrocompass.varpro` -- north (and lambda, B, the torque) by variable-projection least
  squares from a regression start, one record or many;
* :mod:`~schuler.ground_gyrocompass.grid` -- the source's three-stage grid search (vectorised, and one ODE
  integration per cell as the source did);
* :mod:`~schuler.ground_gyrocompass.estimate` -- :func:`identify`, the dispatcher over both methods, and the
  :class:`NorthEstimate` users see;
* :mod:`~schuler.ground_gyrocompass.observations` -- noise, quantisation, CSV records;
* :mod:`~schuler.ground_gyrocompass.monte_carlo` -- accuracy against observation time, predicted and simulated
  with the estimator users run;
* :mod:`~schuler.ground_gyrocompass.reproduction` -- the source's Tables 1-3 against the toolkit;
* :mod:`~schuler.ground_gyrocompass.evaluation`, :mod:`~schuler.ground_gyrocompass.results`,
  :mod:`~schuler.ground_gyrocompass.files`, :mod:`~schuler.ground_gyrocompass.actions`,
  :mod:`~schuler.ground_gyrocompass.report`, :mod:`~schuler.ground_gyrocompass.api` --
  the system on the contract: parameters and ``evaluate`` (a run is its first case
  with histories), how a run renders and the actions' results, the figures and data
  files, ``identify`` and ``simulate``, the report, and ``SYSTEM``;
* :mod:`~schuler.ground_gyrocompass.plots` -- figures.
"""

from schuler.ground_gyrocompass.estimate import NorthEstimate, identify
from schuler.ground_gyrocompass.motion import closed_form, simulate

__all__ = ["NorthEstimate", "closed_form", "identify", "simulate"]
