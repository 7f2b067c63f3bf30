"""
The worked example: a 10 m/s vehicle at 60° N
=============================================

Drozdovich's gyro vertical integrates its accelerometers into velocity. On the
rotating Earth the accelerometers also sense the transport and Coriolis
accelerations W* (eq. (21)); the vertical settles on a slightly tilted
"quasi-steady" position and the integrators carry a systematic velocity error
Δv_y ≈ R ω₂ β_r (eq. (29)): 0.557 m/s in the source's example (printed as
0.67 m/s, an erratum). Around it the error oscillates in two split Schuler
modes whose beat has the Foucault period 2π/(Ω sin φ), not the 24 h the source
names. Compensating W* (the source's "additional devices") removes the
systematic error.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import schuler
from schuler.core.earth import DROZDOVICH
from schuler.gyro_vertical.model import GyroVertical
from schuler.gyro_vertical.quasi_steady import split_schuler_frequencies
from schuler.gyro_vertical.trajectory import GreatCircleTrajectory

latitude = math.radians(60)
path = GreatCircleTrajectory.from_source(latitude, 10.0, frozen=True)  # R = 6.4e6 m, Omega = 7.3e-5 1/s
time = np.arange(0.0, 48 * 3600 + 1, 60.0)

plain = GyroVertical(path, DROZDOVICH.gravity).simulate(time)
compensated = GyroVertical(path, DROZDOVICH.gravity, transport_coriolis_compensation=True).simulate(time)

fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
ax.plot(time / 3600, plain.velocity_error_y, label="Δv_y, as the source builds it")
ax.plot(time / 3600, compensated.velocity_error_y, label="Δv_y, W* compensated")
ax.axhline(np.mean(plain.velocity_error_y), color="k", lw=0.8, ls=":", label="mean")
ax.set_xlabel("time, h")
ax.set_ylabel("velocity error, m/s")
ax.legend()
plt.show()

# %%
# The mean of the simulated error and the split Schuler periods:
omega_2 = path.rate * math.sin(latitude)
fast, slow = split_schuler_frequencies(DROZDOVICH.gravity, path.radius, omega_2)
print(f"mean velocity error {np.mean(plain.velocity_error_y):.3f} m/s (quasi-steady value 0.557 m/s)")
print(f"split Schuler periods {2 * math.pi / fast / 60:.2f} and {2 * math.pi / slow / 60:.2f} min, "
      f"beat {2 * math.pi / (fast - slow) / 3600:.1f} h")

# %%
# The same case through the system, as ``schuler vertical run`` runs it: the
# outputs, the histories (the CSV of ``--out``) and its figures.
run = schuler.get_system("vertical").run(latitude=latitude, earth="drozdovich", duration=48 * 3600.0,
                                         output_step=60.0, trajectory="frozen")
print(f"systematic error {run.velocity_error_y_mean_m_s:.3f} m/s, fitted periods "
      f"{run.fitted_period_fast_s / 60:.2f} and {run.fitted_period_slow_s / 60:.2f} min")
print(run.to_dataframe()[["velocity_error_x_m_s", "velocity_error_y_m_s"]].iloc[::720])
run.plot("vertical_velocity_errors")
plt.show()

# %%
# The reproduction with every printed number: ``schuler vertical reproduce``;
# friction and its dead zone: ``schuler vertical friction --out results/friction``.
