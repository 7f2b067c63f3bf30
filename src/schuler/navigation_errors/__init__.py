"""Schuler-tuned INS error propagation (Bollay 1966, "The Story of 84 Minutes").

Source: Bollay, W., "A Critical Meeting on the Development of Inertial
Navigation - Related to 'The Story of 84 Minutes'", Engineering Case Library,
Stanford University, 1966 (:data:`schuler.references.BOLLAY_1966`); equation
numbers (1)-(4) are its teaching note's, Problems 1-4 its problems.

Modules, from the source's single channel outwards:

- :mod:`~schuler.navigation_errors.single_channel`  five error sources, flat and
  spherical Earth: closed forms (eqs. (2), (4), Problems 1-3), maxima and the
  state-space error equations (eqs. (1), (3));
- :mod:`~schuler.navigation_errors.vertical_channel`  the divergent hover error
  (Problem 4) and the baro-aided second/third-order vertical loop;
- :mod:`~schuler.navigation_errors.effective_period`  the Schuler period under
  thrust and in fast level flight (the source's footnote);
- :mod:`~schuler.navigation_errors.three_d`  the linearised 3-D psi-angle error
  model on the rotating Earth (Schuler, Foucault and Earth-rate modes);
- :mod:`~schuler.navigation_errors.inputs`  the error magnitude (unit by source),
  the Earth constants and the output grid;
- :mod:`~schuler.navigation_errors.evaluation`  ``run``: parameters, outputs and
  ``evaluate`` (vectorised, and the run in full);
- :mod:`~schuler.navigation_errors.reproduction`  Problem 3's table and the hover
  number with the source's constants, the ``plot`` action and the report;
- :mod:`~schuler.navigation_errors.actions`  ``vertical`` and ``period``;
  :mod:`~schuler.navigation_errors.three_d_run`  ``three-d``;
- :mod:`~schuler.navigation_errors.results`, :mod:`~schuler.navigation_errors.files`,
  :mod:`~schuler.navigation_errors.plots`  result types, the one file writer, figures;
- :mod:`~schuler.navigation_errors.api`  ``SYSTEM`` (``schuler errors``).
"""
