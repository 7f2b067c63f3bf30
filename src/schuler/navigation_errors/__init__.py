"""Schuler-tuned INS error propagation (source 002: Bollay, "The Story of 84 Minutes").

Modules, from the source's single channel outwards:

- :mod:`~schuler.navigation_errors.single_channel`  five error sources, flat and
  spherical Earth: closed forms, maxima and the state-space error equations;
- :mod:`~schuler.navigation_errors.vertical_channel`  the divergent hover error
  (Problem 4) and the baro-aided second/third-order vertical loop;
- :mod:`~schuler.navigation_errors.effective_period`  the Schuler period under
  thrust and in fast level flight (the source's footnote);
- :mod:`~schuler.navigation_errors.three_d`  the linearised 3-D psi-angle error
  model on the rotating Earth (Schuler, Foucault and Earth-rate modes);
- :mod:`~schuler.navigation_errors.reproduction`  Problem 3's table and the
  hover number with the source's constants;
- :mod:`~schuler.navigation_errors.api`  run / reproduce / report / sweep and ``SYSTEM``.
"""
