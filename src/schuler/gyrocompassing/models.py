"""Linear models of physical gyrocompassing of a semi-analytic platform INS.

Frames (the KPI manual, Sec. 2): xi eta zeta is the geographic frame (xi east,
eta north, zeta up); x_g y_g z_g is the horizontal frame turned by the azimuth A
about zeta; xyz is the platform. The platform is off x_g y_g z_g by delta
(azimuth, about z) and the level angles nu (about x) and mu (about y); the
frame xi_P eta_P zeta_P modelled by the platform is off xi eta zeta by delta,
beta (about xi) and alpha (about eta), with (1.11)

    beta = nu cos A + mu sin A,    alpha = -nu sin A + mu cos A.

On a fixed base U_eta = U cos(phi), U_zeta = U sin(phi), U_xi = 0, and in the
platform axes U_x = -U cos(phi) sin A, U_y = U cos(phi) cos A, U_z = U sin(phi).

The control law (1.6) with the accelerometers on a fixed base (1.8),
a_x = -g mu + Delta a_x, a_y = g nu + Delta a_y, and the gains
c_gamma = -c1 g, c_a = c2 g, gives the full model (1.17). Its printed third
line pairs cos A with mu and sin A with nu, and its printed sign of eps_x does
not follow from (1.8): -c1 a_x = -c_gamma (mu - eps_x) and
c2 a_eta = c2 (a_y cos A - a_x sin A) = c_a [(nu + eps_y) cos A + (mu - eps_x) sin A]
= c_a (beta + eps_beta), as (1.10) and (1.11) require. The models here use the
corrected equations; :func:`printed_mu_nu_model` keeps the printed ones only to
show that they make the azimuth loop unstable.

Every model takes the same six constant inputs (SI), in this order
(:data:`INPUTS`): the residual drifts Delta omega_dx, Delta omega_dy,
Delta omega_dz (rad/s, platform axes; Delta omega_d = estimate - true drift),
the latitude input error Delta phi (rad, linearised as in (1.16)), and the
accelerometer errors Delta a_x, Delta a_y (m/s^2; eps = Delta a / g).

Every builder accepts scalars or arrays of length N for its parameters; with any
array it returns a batch of N models ((N, n, n) matrices) for sweeps and Monte
Carlo on :mod:`schuler.core.lti`.
"""

from __future__ import annotations

import numpy as np

from schuler.core.earth import EARTH_RATE, STANDARD_GRAVITY
from schuler.core.geometry import earth_rate_north_up, level_frame_earth_rate
from schuler.core.lti import StateSpace

INPUTS = ("drift_x", "drift_y", "drift_z", "latitude_error", "accel_error_x", "accel_error_y")
"""Names of the six inputs of every model, in order."""

INPUT_UNITS = ("rad/s", "rad/s", "rad/s", "rad", "m/s^2", "m/s^2")

MODELS = ("full", "full-ab", "simplified")
"""Model names: full in (mu, nu, delta) (1.17), full in (beta, alpha, delta) (1.18), simplified (1.19)."""


def _broadcast(*values):
    """Float arrays of a common shape (), or (N,) when any value is an array."""
    arrays = np.broadcast_arrays(*[np.asarray(v, dtype=float) for v in values])
    if arrays[0].ndim > 1:
        raise ValueError("model parameters must be scalars or 1-D arrays")
    return arrays


def _assemble(rows, shape):
    """Stack nested lists of (broadcast) arrays into matrices of shape (*shape, r, c)."""
    return np.stack([np.stack([np.broadcast_to(np.asarray(e, dtype=float), shape) for e in row], -1)
                     for row in rows], -2)


def earth_rate_components(latitude, azimuth, earth_rate=EARTH_RATE):
    """Earth-rate components on a fixed base (the KPI manual, Sec. 2).

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A of the platform's y_g axis from north towards east, rad
        (x_g points to A + 90 deg).
    earth_rate : float
        Earth rotation rate U, rad/s.

    Returns
    -------
    dict of ndarray
        ``U_eta`` = U cos(phi), ``U_z`` (= U_zeta = U sin(phi)) and the
        platform-axis ``U_x`` = -U cos(phi) sin A, ``U_y`` = U cos(phi) cos A, rad/s.

    Notes
    -----
    The platform's (y, x, -z) axes form the core's level frame at azimuth A
    (:func:`~schuler.core.geometry.level_frame_earth_rate`). No pole check: the
    models hold at any latitude; the closed forms refuse the poles.

    Examples
    --------
    >>> c = earth_rate_components(0.0, np.pi / 2)
    >>> float(c["U_eta"]) == EARTH_RATE, round(float(c["U_x"] / EARTH_RATE), 12)
    (True, -1.0)
    """
    phi, A = _broadcast(latitude, azimuth)
    U_y, U_x, down = level_frame_earth_rate(phi, A, earth_rate)
    U_eta, _ = earth_rate_north_up(phi, earth_rate)
    return {"U_eta": U_eta, "U_z": -down, "U_x": U_x, "U_y": U_y}


def full_mu_nu_model(latitude, azimuth, c_gamma, c_a, *, earth_rate=EARTH_RATE, gravity=STANDARD_GRAVITY) -> StateSpace:
    """Full model in the platform's level angles (mu, nu) and azimuth delta: (1.12)/(1.17) corrected.

    States (mu, nu, delta), rad; inputs :data:`INPUTS`; outputs delta, beta,
    alpha, mu, nu (rad) and the azimuth rate delta_rate (rad/s)::

        mu'    = -c_gamma (mu - eps_x) + dU_y - dw_dy - nu U_z - delta U_x
        nu'    = -c_gamma (nu + eps_y) + dU_x - dw_dx + mu U_z + delta U_y
        delta' = -c_a [(nu + eps_y) cos A + (mu - eps_x) sin A]
                 - dU_z + dw_dz - nu U_y + mu U_x

    with (1.16) dU_x = U sin(phi) sin(A) dphi, dU_y = -U sin(phi) cos(A) dphi,
    dU_z = U cos(phi) dphi.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A, rad.
    c_gamma : float or ndarray
        Level correction gain c_Gamma, 1/s.
    c_a : float or ndarray
        Azimuth correction gain c_a, 1/s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g turning accelerometer errors into eps = Delta a / g, m/s^2.

    Examples
    --------
    >>> m = full_mu_nu_model(np.radians(50), 0.0, 0.0533, 23.7)
    >>> bool(np.all(m.eigenvalues().real < 0))
    True
    """
    return _mu_nu_model(latitude, azimuth, c_gamma, c_a, earth_rate, gravity, printed=False)


def printed_mu_nu_model(latitude, azimuth, c_gamma, c_a, *, earth_rate=EARTH_RATE,
                        gravity=STANDARD_GRAVITY) -> StateSpace:
    """The (mu, nu, delta) model exactly as (1.17) is printed, for demonstration only.

    The printed third line, delta' = -c_a [(mu + eps_x) cos A + (nu + eps_y) sin A] ...,
    and the printed mu line, -c_gamma (mu + eps_x), contradict (1.8), (1.10) and
    (1.11). At A = 0 the azimuth loop delta -> nu -> mu -> delta then has the
    positive loop gain c_a U_y U_z and the model diverges. Parameters as in
    :func:`full_mu_nu_model`.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A, rad.
    c_gamma : float or ndarray
        Level correction gain c_Gamma, 1/s.
    c_a : float or ndarray
        Azimuth correction gain c_a, 1/s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g turning accelerometer errors into eps = Delta a / g, m/s^2.

    Returns
    -------
    StateSpace
        States (mu, nu, delta), rad; inputs :data:`INPUTS`; outputs delta, beta, alpha, mu, nu (rad) and
        delta_rate (rad/s), as :func:`full_mu_nu_model`'s; batched over the broadcast shape of the arguments.

    Examples
    --------
    >>> m = printed_mu_nu_model(np.radians(50), 0.0, 0.0533, 23.7)
    >>> bool(np.max(m.eigenvalues().real) > 0)
    True
    """
    return _mu_nu_model(latitude, azimuth, c_gamma, c_a, earth_rate, gravity, printed=True)


def _mu_nu_model(latitude, azimuth, c_gamma, c_a, earth_rate, gravity, printed):
    phi, A, cg, ca = _broadcast(latitude, azimuth, c_gamma, c_a)
    shape = phi.shape
    U = earth_rate_components(phi, A, earth_rate)
    U_x, U_y, U_z = U["U_x"], U["U_y"], U["U_z"]
    sin_A, cos_A = np.sin(A), np.cos(A)
    U_sin, U_cos = U_z, U["U_eta"]
    zero = np.zeros(shape)
    if printed:
        delta_row = [-ca * cos_A + U_x, -ca * sin_A - U_y, zero]
        delta_accel = [-ca * cos_A / gravity, -ca * sin_A / gravity]
        mu_accel = -cg / gravity
    else:
        delta_row = [-ca * sin_A + U_x, -ca * cos_A - U_y, zero]
        delta_accel = [ca * sin_A / gravity, -ca * cos_A / gravity]
        mu_accel = cg / gravity
    A_matrix = _assemble([[-cg, -U_z, -U_x], [U_z, -cg, U_y], delta_row], shape)
    B_matrix = _assemble(
        [
            [zero, -1.0, zero, -U_sin * cos_A, mu_accel, zero],
            [-1.0, zero, zero, U_sin * sin_A, zero, -cg / gravity],
            [zero, zero, 1.0, -U_cos, *delta_accel],
        ],
        shape,
    )
    # outputs: delta, beta, alpha (1.11), mu, nu, and delta' = third rows of A and B
    C_matrix = _assemble(
        [[zero, zero, 1.0], [sin_A, cos_A, zero], [cos_A, -sin_A, zero], [1.0, zero, zero], [zero, 1.0, zero],
         delta_row],
        shape,
    )
    D_matrix = np.zeros((*shape, 6, 6))
    D_matrix[..., 5, :] = B_matrix[..., 2, :]
    return StateSpace(
        A_matrix, B_matrix, C_matrix, D_matrix,
        states=("mu", "nu", "delta"), inputs=INPUTS,
        outputs=("delta", "beta", "alpha", "mu", "nu", "delta_rate"),
        state_units=("rad",) * 3, output_units=("rad",) * 5 + ("rad/s",),
    )


def _level_input_rows(A, cg, ca, U_sin, U_cos, gravity, zero):
    """Input rows of beta', alpha', delta' in (1.18): rotated drifts (1.14), eps_beta, eps_alpha."""
    sin_A, cos_A = np.sin(A), np.cos(A)
    # dw_dxi = dw_dx cos A + dw_dy sin A; eps_beta = eps_y cos A - eps_x sin A
    beta_row = [-cos_A, -sin_A, zero, zero, cg * sin_A / gravity, -cg * cos_A / gravity]
    # dw_deta = -dw_dx sin A + dw_dy cos A; eps_alpha = -(eps_x cos A + eps_y sin A); dU_eta = -U sin(phi) dphi
    alpha_row = [sin_A, -cos_A, zero, -U_sin, cg * cos_A / gravity, cg * sin_A / gravity]
    delta_row = [zero, zero, 1.0 + zero, -U_cos, ca * sin_A / gravity, -ca * cos_A / gravity]
    return beta_row, alpha_row, delta_row


def full_alpha_beta_model(latitude, azimuth, c_gamma, c_a, *, earth_rate=EARTH_RATE,
                          gravity=STANDARD_GRAVITY) -> StateSpace:
    """Full model in the geographic level angles (beta, alpha) and azimuth delta: (1.18).

    States (beta, alpha, delta), rad; inputs :data:`INPUTS`; outputs delta,
    beta, alpha, mu, nu (rad) and delta_rate (rad/s)::

        beta'  = -c_gamma (beta + eps_beta) - dw_dxi + alpha U_z + delta U_eta
        alpha' = -c_gamma (alpha + eps_alpha) - dw_deta - beta U_z + dU_eta
        delta' = -c_a (beta + eps_beta) + dw_dz - beta U_eta - dU_z

    with eps_beta = eps_y cos A - eps_x sin A (= Delta a_eta / g; the source's
    closing line has the wrong sign on eps_x), eps_alpha = -(eps_x cos A + eps_y sin A),
    dw_dxi = dw_dx cos A + dw_dy sin A, dw_deta = -dw_dx sin A + dw_dy cos A,
    dU_eta = -U sin(phi) dphi, dU_z = U cos(phi) dphi. It is (1.17) corrected,
    rotated by (1.11). Parameters as in :func:`full_mu_nu_model`.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A, rad.
    c_gamma : float or ndarray
        Level correction gain c_Gamma, 1/s.
    c_a : float or ndarray
        Azimuth correction gain c_a, 1/s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g turning accelerometer errors into eps = Delta a / g, m/s^2.

    Returns
    -------
    StateSpace
        States (beta, alpha, delta), rad; batched over the broadcast shape of the arguments.

    Examples
    --------
    >>> m = full_alpha_beta_model(np.radians([0, 50]), 0.0, 0.0533, 23.7)
    >>> m.A.shape
    (2, 3, 3)
    """
    phi, A, cg, ca = _broadcast(latitude, azimuth, c_gamma, c_a)
    shape = phi.shape
    U = earth_rate_components(phi, A, earth_rate)
    U_eta, U_z = U["U_eta"], U["U_z"]
    zero = np.zeros(shape)
    sin_A, cos_A = np.sin(A), np.cos(A)
    A_matrix = _assemble([[-cg, U_z, U_eta], [-U_z, -cg, zero], [-ca - U_eta, zero, zero]], shape)
    rows = _level_input_rows(A, cg, ca, U_z, U_eta, gravity, zero)
    B_matrix = _assemble(rows, shape)
    # outputs: delta, beta, alpha, mu = beta sin A + alpha cos A, nu = beta cos A - alpha sin A, delta'
    C_matrix = _assemble(
        [[zero, zero, 1.0], [1.0, zero, zero], [zero, 1.0, zero], [sin_A, cos_A, zero], [cos_A, -sin_A, zero],
         [-ca - U_eta, zero, zero]],
        shape,
    )
    D_matrix = np.zeros((*shape, 6, 6))
    D_matrix[..., 5, :] = B_matrix[..., 2, :]
    return StateSpace(
        A_matrix, B_matrix, C_matrix, D_matrix,
        states=("beta", "alpha", "delta"), inputs=INPUTS,
        outputs=("delta", "beta", "alpha", "mu", "nu", "delta_rate"),
        state_units=("rad",) * 3, output_units=("rad",) * 5 + ("rad/s",),
    )


def simplified_model(latitude, azimuth, c_gamma, c_a, *, earth_rate=EARTH_RATE, gravity=STANDARD_GRAVITY) -> StateSpace:
    """Simplified model (1.19): (1.18) without the cross-couplings beta U_z, alpha U_z, beta U_eta.

    States (beta, delta), rad; inputs :data:`INPUTS`; outputs delta, beta (rad)
    and delta_rate (rad/s)::

        beta'  = -c_gamma (beta + eps_beta) - dw_dxi + delta U_eta
        delta' = -c_a (beta + eps_beta) + dw_dz - dU_z

    Valid after levelling (tilts of a few arcminutes) with c_gamma, c_a much larger
    than the Earth rate. Its characteristic equation p^2 + c_gamma p + U_eta c_a = 0
    gives (1.20). Parameters as in :func:`full_mu_nu_model`.

    Parameters
    ----------
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A, rad.
    c_gamma : float or ndarray
        Level correction gain c_Gamma, 1/s.
    c_a : float or ndarray
        Azimuth correction gain c_a, 1/s.
    earth_rate : float
        U, rad/s.
    gravity : float
        g turning accelerometer errors into eps = Delta a / g, m/s^2.

    Returns
    -------
    StateSpace
        States (beta, delta), rad; batched over the broadcast shape of the arguments.

    Examples
    --------
    >>> m = simplified_model(np.radians(50), 0.0, 0.0533, 23.7)
    >>> m.states
    ('beta', 'delta')
    """
    phi, A, cg, ca = _broadcast(latitude, azimuth, c_gamma, c_a)
    shape = phi.shape
    U_eta, U_z = earth_rate_north_up(phi, earth_rate)
    zero = np.zeros(shape)
    A_matrix = _assemble([[-cg, U_eta], [-ca, zero]], shape)
    beta_row, _, delta_row = _level_input_rows(A, cg, ca, U_z, U_eta, gravity, zero)
    B_matrix = _assemble([beta_row, delta_row], shape)
    C_matrix = _assemble([[zero, 1.0], [1.0, zero], [-ca, zero]], shape)
    D_matrix = np.zeros((*shape, 3, 6))
    D_matrix[..., 2, :] = B_matrix[..., 1, :]
    return StateSpace(
        A_matrix, B_matrix, C_matrix, D_matrix,
        states=("beta", "delta"), inputs=INPUTS,
        outputs=("delta", "beta", "delta_rate"),
        state_units=("rad",) * 2, output_units=("rad", "rad", "rad/s"),
    )


BUILDERS = {"full": full_mu_nu_model, "full-ab": full_alpha_beta_model, "simplified": simplified_model}
"""Model name -> builder."""


def build_model(model: str, latitude, azimuth, c_gamma, c_a, **constants) -> StateSpace:
    """Build the model named ``model`` (one of :data:`MODELS`); other arguments as :func:`full_mu_nu_model`.

    Parameters
    ----------
    model : str
        One of :data:`MODELS`.
    latitude : float or ndarray
        Latitude phi, rad.
    azimuth : float or ndarray
        Azimuth A, rad.
    c_gamma : float or ndarray
        Level correction gain c_Gamma, 1/s.
    c_a : float or ndarray
        Azimuth correction gain c_a, 1/s.
    **constants
        ``earth_rate`` (rad/s) and ``gravity`` (m/s^2).

    Examples
    --------
    >>> build_model("simplified", 0.8, 0.5, 0.05, 20.0).n_states
    2
    """
    return BUILDERS[model](latitude, azimuth, c_gamma, c_a, **constants)


def initial_state(model: str, delta0, beta0=0.0, alpha0=0.0, azimuth=0.0) -> np.ndarray:
    """Initial state vector of a model from the misalignment (delta0, beta0, alpha0), rad.

    For the (mu, nu) model the level angles are rotated by (1.11):
    mu = beta sin A + alpha cos A, nu = beta cos A - alpha sin A. The simplified
    model has no alpha. Scalars give shape (n,), arrays of length N give (N, n).

    Parameters
    ----------
    model : str
        One of :data:`MODELS`.
    delta0, beta0, alpha0 : float or ndarray
        Initial azimuth error and level errors, rad.
    azimuth : float or ndarray
        Azimuth A, rad.

    Examples
    --------
    >>> initial_state("full", 0.01, 0.0, 0.0)
    array([0.  , 0.  , 0.01])
    """
    d, b, a, A = _broadcast(delta0, beta0, alpha0, azimuth)
    columns: tuple[np.ndarray, ...]
    if model == "full":
        columns = (b * np.sin(A) + a * np.cos(A), b * np.cos(A) - a * np.sin(A), d)
    elif model == "full-ab":
        columns = (b, a, d)
    else:
        columns = (b, d)
    return np.stack(columns, axis=-1)


def platform_drifts(azimuth, drift_x=0.0, drift_y=0.0, drift_east=0.0, drift_north=0.0):
    """Residual drifts in platform axes x, y from platform-axis and east/north parts, rad/s.

    Inverts (1.14): dw_dx = dw_dxi cos A - dw_deta sin A, dw_dy = dw_dxi sin A + dw_deta cos A,
    added to the platform-axis parts.

    Parameters
    ----------
    azimuth : float or ndarray
        Azimuth A, rad.
    drift_x, drift_y : float or ndarray
        Drifts about the platform axes x, y, rad/s.
    drift_east, drift_north : float or ndarray
        Drifts about east and north, rad/s.

    Examples
    --------
    >>> x, y = platform_drifts(np.pi / 2, drift_east=1.0)
    >>> round(float(x), 12), round(float(y), 12)
    (0.0, 1.0)
    """
    A, dx, dy, de, dn = _broadcast(azimuth, drift_x, drift_y, drift_east, drift_north)
    return dx + de * np.cos(A) - dn * np.sin(A), dy + de * np.sin(A) + dn * np.cos(A)
