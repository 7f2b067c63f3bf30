"""Aided navigation: the INS corrected by external measurements (GNSS) in an error-state Kalman filter.

* :mod:`~schuler.aided.error_state`: the 15- or 21-state error model, its sensor-error processes
  and its exact discretisation (spec 07).
* :mod:`~schuler.aided.measurements`: GNSS position and velocity at a lever arm: residuals and H.
* :mod:`~schuler.aided.kalman`: predict and the gated Joseph-form update on a batch of members.
* :mod:`~schuler.aided.ekf`: the closed-loop filter around :mod:`schuler.navigate`'s strapdown step.
"""
