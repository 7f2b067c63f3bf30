"""
Nonlinear INS: a velocity error and a gyro bias at rest
=======================================================

The strapdown INS at rest at 45 deg N (NED, body x forward / y right / z down,
errors = computed - true), navigated without linearisation on WGS-84. An
initial north velocity error of 0.1 m/s makes the Schuler oscillation
(ΔV / ω_s) sin(ω_s t), period 84.4 min; a 0.01 deg/h bias of the x
(north-pointing) gyro adds the slow growth of a tilt that the oscillation
carries along. The vertical channel is held to the truth (``off``).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import schuler

navigate = schuler.get_system("navigate")
common = dict(latitude=math.radians(45), duration=5400.0, imu_rate=5.0, output_step=30.0)
velocity = navigate.run(velocity_error_north=0.1, **common)
with_gyro = navigate.run(velocity_error_north=0.1, gyro_bias_x=math.radians(0.01) / 3600, **common)

# each run's error histories, indexed by time t_s (SI units in the column names)
alone, both = velocity.to_dataframe(), with_gyro.to_dataframe()
t = alone.index.to_numpy()
schuler_rate = math.sqrt(9.806 / 6.371e6)  # rad/s, the flat-Earth Schuler frequency
fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
ax.plot(t / 60, alone["position_error_north_m"], label="0.1 m/s north velocity error")
ax.plot(t / 60, both["position_error_north_m"], label="... and 0.01 deg/h x-gyro bias")
ax.plot(t / 60, 0.1 / schuler_rate * np.sin(schuler_rate * t), "k:", lw=0.9, label="(ΔV / ω_s) sin ω_s t")
ax.set(xlabel="time, min", ylabel="north position error, m")
ax.legend()
plt.show()

# %%
# The final and largest errors are the outputs a sweep collects (SI):
for name in ("final_position_error_north_m", "max_abs_position_error_north_m", "final_heading_error_rad"):
    print(f"{name:32s} {velocity.outputs[name]: .4g}   {with_gyro.outputs[name]: .4g}")

# %%
# The scenario file runs the same case for an hour at 100 Hz; its Monte Carlo
# draws the biases and the velocity error per member::
#
#     schuler run examples/navigate_stationary.toml
#     schuler sweep examples/navigate_stationary.toml --monte-carlo 200 --out sweep-navigate
