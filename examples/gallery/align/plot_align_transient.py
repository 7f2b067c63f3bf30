"""
Gyrocompassing: the azimuth transient and its steady state
==========================================================

In physical gyrocompassing the platform's accelerometers sense the apparent
drift of an axis that is off the horizontal Earth rate U_η = U cos φ and drive
the platform in level and azimuth (KPI manual, (1.6)). The azimuth error δ
obeys δ'' + c_Γ δ' + c_a U_η δ = ... (1.20): a damped oscillator that settles
on δ_y = Δω_dξ / (U cos φ) + ... (1.21). Here a 1° initial azimuth error
settles with the design T = 30 s, ζ = 0.8, and a 0.01 deg/h east drift leaves
3.56 arcmin at 50° N; the full model (1.18) and the simplified (1.19) agree.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import schuler

align = schuler.get_system("align")
drift = math.radians(0.01) / 3600  # rad/s
full = align.run(latitude=math.radians(50), drift_east=drift)
simplified = align.run(latitude=math.radians(50), drift_east=drift, model="simplified")

fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
for result, label in ((full, "full model (1.18)"), (simplified, "simplified (1.19)")):
    history = result.to_dataframe()  # align_time_history, indexed by t_s
    ax.plot(history.index, np.degrees(history["delta_rad"]) * 60, label=label)
ax.axhline(math.degrees(full.azimuth_error_analytic_rad) * 60, color="k", ls=":", lw=0.8, label="steady state (1.21)")
ax.axvline(full.settling_time_s, color="grey", ls="--", lw=0.8, label="settling time 5 / h")
ax.set(xlabel="time, s", ylabel="azimuth error δ, arcmin", ylim=(-20, 65))
ax.legend()
plt.show()

# %%
# The system's own figures of a run, as ``--out`` writes them:
print(full)
full.plot("align_phase_trajectory")
plt.show()

# %%
# ``evaluate_values`` is what a sweep calls: the closed forms over many cases at
# once. The same drift costs more azimuth at high latitude, where U_η is small:
latitudes = np.radians(np.arange(0.0, 71.0, 10.0))
batch = align.evaluate_values({"latitude": latitudes, "drift_east": np.full(latitudes.size, drift)}, fidelity="closed")
for phi, error in zip(np.degrees(latitudes), np.degrees(batch["azimuth_error_analytic_rad"]) * 60):
    print(f"latitude {phi:4.0f} deg: azimuth error {error:6.2f} arcmin")

# %%
# The same sweep with a Monte Carlo of residual drifts, stored and resumable::
#
#     schuler sweep examples/align_gyrocompassing.toml --param latitude=0:80:5 \
#         --monte-carlo 200 --out results/sweep-align
