"""Where the nonlinear INS's results mean what they say: the mechanization's domain and the models' validity.

Two limits, checked on every run of :func:`~schuler.navigate.mechanization.navigate`:

* **The domain of the mechanization** (:func:`schuler.navigate._kernels.inside_domain`, checked
  at every IMU step): the computed height between -a/2 and a, the position off the poles, the
  speed below 100 km/s. Outside it the equations end (R + h -> 0 under the Earth's centre,
  tan L at a pole) or gravity's height series runs away, so the run cannot be continued: the
  kernel stops the member and :func:`domain_message` says where and when
  (:class:`~schuler.exceptions.SimulationError`).
* **The validity of the models** (:func:`validity_messages`, on the output histories): a
  computed height outside :data:`VALID_HEIGHTS`, where WGS-84 normal gravity no longer models
  the Earth's, and attitude errors beyond :data:`SMALL_ANGLE`, where the small-angle (linear)
  error models the nonlinear INS referees no longer hold. The run is finite but degraded: a
  :class:`ModelValidityWarning` and the result's ``warnings`` say so.
"""

from __future__ import annotations

import math

import numpy as np

from schuler.exceptions import renamed_keywords
from schuler.navigate import _kernels

VALID_HEIGHTS = (-1.1e4, 1.2e5)
"""Heights (m) where WGS-84 normal gravity's height series (Groves 2013, eq. (2.139)) models gravity: below -11 km
(deeper than the deepest ocean) it continues free-air gravity downwards, ignoring the masses above (the Bouguer
term, 0.11 mGal/m: 1.2 mg at -11 km); above 120 km its truncation, 4 (h / a)^3 of g, exceeds 2.7e-5 g. Both lie
beyond the start heights the parameters allow (-10 km .. 100 km), so that a run started at a limit warns only when
its height really leaves them."""

SMALL_ANGLE = 0.1
"""Largest attitude error (rad, 5.7 deg) of the small-angle error models: their first-order terms (sin x ~ x,
cos x ~ 1) err by x^2 / 2 = 0.5 % there."""

_FREE_HINT = ("; a free vertical channel diverges (its height error e-folds in about 570 s): hold it "
              "(vertical channel off) or aid it (baro), or shorten the duration")


class ModelValidityWarning(UserWarning):
    """A run left the range where its gravity model or the small-angle error models hold (its numbers are finite)."""


def _who(members: np.ndarray, ids: np.ndarray, batch: int | None) -> str:
    """`` (member 3)`` or `` (2 of 10 members, member 3 first)`` for the members concerned; nothing for one."""
    if batch is None or batch == 1:
        return ""
    first = int(ids[members[0]])
    return f" (member {first})" if members.size == 1 else f" ({members.size} of {batch} members, member {first} first)"


def domain_message(states: np.ndarray, ids: np.ndarray, batch: int | None, dt: float, vertical_channel: str) -> str:
    """The one line that reports members stopped outside the mechanization's domain.

    Parameters
    ----------
    states : ndarray, shape (N, STATE_SIZE)
        Members' states after a chunk; a stopped member's row is its first state outside the domain
        and its ``LEFT_AT`` entry the sample number, number of.
    ids : ndarray of int, shape (N,)
        Global member numbers.
    batch : int or None
        Batch size (None: a single run, no member named).
    dt : float
        IMU interval, s.
    vertical_channel : str
        The run's vertical channel (a free one gets a hint).

    Returns
    -------
    str
        What left the domain, when, and why the run cannot go on.
    """
    left = np.flatnonzero(states[:, _kernels.LEFT_AT])
    left = left[np.argsort(states[left, _kernels.LEFT_AT], kind="stable")]
    state = states[left[0]]
    t = state[_kernels.LEFT_AT] * dt
    h = state[_kernels.HGT]
    speed = float(np.linalg.norm(state[_kernels.VEL:_kernels.VEL + 3]))
    when = f"at t = {t:,.6g} s{_who(left, ids, batch)}"
    if h <= _kernels.LOWEST_HEIGHT:
        what = (f"the computed height fell below {_kernels.LOWEST_HEIGHT / 1e3:,.0f} km (half way to the Earth's "
                f"centre) {when}, where the navigation equations' frame rates v / (R + h) grow without bound")
    elif h >= _kernels.HIGHEST_HEIGHT:
        what = (f"the computed height rose above {_kernels.HIGHEST_HEIGHT / 1e3:,.0f} km (one Earth radius) {when}, "
                "where gravity's height series grows again with height and the height runs away")
    elif abs(state[_kernels.COS_LAT]) <= _kernels.POLE_COSINE:
        what = (f"the computed position reached a pole {when}, where the north-pointing latitude-longitude "
                "mechanization is singular")
    else:
        what = (f"the computed speed reached {speed:,.3g} m/s {when}, beyond the {_kernels.HIGHEST_SPEED:,.0f} m/s "
                "that any trajectory or error allowed stays below")
    hint = _FREE_HINT if vertical_channel == "free" else ": use smaller errors or a shorter duration"
    return f"the run cannot be continued: {what}{hint}"


@renamed_keywords(t_s="t", computed_height_m="computed_height", attitude_error_rad="attitude_error")
def validity_messages(t: np.ndarray, computed_height: np.ndarray, attitude_error: np.ndarray,
                      ids: np.ndarray, batch: int | None, vertical_channel: str) -> list[str]:
    """What a finite run says about leaving its models' validity (empty when it stayed inside).

    Parameters
    ----------
    t : ndarray, shape (n_out,)
        Output times, s.
    computed_height : ndarray, shape (N, n_out)
        The computed height at the output times, m.
    attitude_error : ndarray, shape (N, n_out, 3)
        Error rotation vectors, rad.
    ids : ndarray of int, shape (N,)
        Global member numbers.
    batch : int or None
        Batch size, members (None: a single run).
    vertical_channel : str
        The run's vertical channel (a free one gets a hint).

    Returns
    -------
    list of str
        One message per limit crossed: the height range of :data:`VALID_HEIGHTS`, the attitude
        error of :data:`SMALL_ANGLE`.

    Examples
    --------
    >>> t = np.array([0.0, 10.0])
    >>> validity_messages(t, np.array([[0.0, 2e5]]), np.zeros((1, 2, 3)), np.array([0]), None, "off")[0][:60]
    'the computed height left -11 km .. 120 km at t = 10 s and re'
    """
    messages = []
    low, high = VALID_HEIGHTS
    outside = (computed_height < low) | (computed_height > high)
    if outside.any():
        members = np.flatnonzero(outside.any(axis=1))
        first = outside.argmax(axis=1)
        member = members[np.argmin(first[members])]
        k = int(first[member])
        worst = computed_height[members]
        extreme = float(worst.min() if worst.min() < low else worst.max())
        hint = _FREE_HINT if vertical_channel == "free" else ""
        messages.append(f"the computed height left {low / 1e3:,.0f} km .. {high / 1e3:,.0f} km at t = {t[k]:,.6g} s"
                        f"{_who(members, ids, batch)} and reached {extreme / 1e3:,.4g} km: outside that range WGS-84 "
                        f"normal gravity no longer models the Earth's, so later errors are the model's{hint}")
    angle = np.linalg.norm(attitude_error, axis=-1)
    large = angle > SMALL_ANGLE
    if large.any():
        members = np.flatnonzero(large.any(axis=1))
        first = large.argmax(axis=1)
        member = members[np.argmin(first[members])]
        k = int(first[member])
        messages.append(f"the attitude error passed {math.degrees(SMALL_ANGLE):.2g} deg at t = {t[k]:,.6g} s"
                        f"{_who(members, ids, batch)} and reached {math.degrees(float(angle[members].max())):.3g} "
                        "deg: beyond the small angles of the linear error models (0.5 % from their first-order "
                        "terms), which this run no longer referees")
    return messages
