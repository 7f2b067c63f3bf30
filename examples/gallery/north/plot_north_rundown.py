"""
North from a rotor run-down
===========================

A two-degree ground gyrocompass whose rotor is spun up once and then runs down
naturally, H = H_m exp(−λ t): the sensitive element swings about north with a
slowly growing period, α'' + B exp(−λ t) α = 0 with B = H_m Ω_h / J (eqs.
(1)-(4) of Fedorov, Kikot and Shtefan). Its solution is a combination of the
Bessel functions J0 and Y0 of z = (2/λ) sqrt(B exp(−λ t)) (eq. (9)). The
instrument reads the motion relative to the start, α − α0; fitting eq. (9) to
200 s of readings gives α0 and so north, here with λ and B unknown too and
1 arcsec of read-out noise.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from schuler.ground_gyrocompass import closed_form, identify
from schuler.ground_gyrocompass.motion import directive_coefficient
from schuler.ground_gyrocompass.observations import observe

# the source's machine experiment (J, Omega_h, H_m, lambda, alpha0, alpha0_dot)
inertia, omega_h, hm, decay_rate = 1.1607e-3, 3.65e-5, 0.432, 2.15e-3
alpha0, alpha0_dot = 3.69 * math.pi / 540, 4.08e-4
time = np.arange(0.0, 201.0, 1.0)
angle = closed_form(time, alpha0, alpha0_dot, decay_rate, directive_coefficient(hm, omega_h, inertia))
arcsec = math.radians(1 / 3600)
reading = observe(angle, alpha0, noise=1 * arcsec, rng=np.random.default_rng(3))

estimate = identify(time, reading, 4, decay_rate=decay_rate, hm=hm, inertia=inertia, omega_h=omega_h)

fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 5), sharex=True, layout="constrained")
top.plot(time, np.degrees(reading) * 60, ".", ms=3, label="reading α − α0")
top.plot(time, np.degrees(reading - estimate.residuals) * 60, label="fitted eq. (9)")
top.set_ylabel("arcmin")
top.legend()
bottom.plot(time, estimate.residuals / arcsec, ".", ms=3)
bottom.set(xlabel="time since release, s", ylabel="residual, arcsec")
plt.show()

# %%
# North is −α0 from the rotor axis at release; its standard error comes from
# the Jacobian of the fit (λ and B are strongly correlated):
error = math.degrees(estimate.north_rad + alpha0) * 3600
assert estimate.north_std_rad is not None  # alpha0 is identified, so it has a standard error
print(f"true north {math.degrees(-alpha0):.6f} deg, identified {math.degrees(estimate.north_rad):.6f} deg: "
      f"error {error:+.3f} arcsec, standard error {math.degrees(estimate.north_std_rad) * 3600:.3f} arcsec")
print(f"lambda {estimate.decay_rate:.6g} 1/s (true {decay_rate}), H_m {estimate.Hm:.5g} N m s (true {hm})")

# %%
# The source's Tables 1-3 (grid search) against the least-squares fit:
# ``schuler north reproduce --unknowns 4``; accuracy against observation time:
# ``schuler north run --monte-carlo 200``.
