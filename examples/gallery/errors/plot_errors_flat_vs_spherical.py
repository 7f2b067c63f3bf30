"""
Five error sources, flat Earth against the Schuler loop
=======================================================

Bollay's Problem 3: a 5060-mile missile flight of 10,120 s with five error
sources. On a flat Earth a tilt or an accelerometer bias grows as t², a gyro
drift as t³; on the sphere the platform is kept level by feeding the computed
distance back as a rotation, which turns the errors into 84-minute Schuler
oscillations (and a drift into a linear growth). The curves are the closed
forms of :mod:`schuler.navigation_errors.single_channel` with Bollay's own
constants (R = 3960 statute miles, T = 5060 s); the dots are the exact
simulation of the error equations, which must lie on them.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

import schuler
from schuler.navigation_errors.single_channel import flat_error, simulate_error, spherical_error

FOOT = 0.3048  # m
MILE = 1609.344  # m, statute
radius = 3960 * MILE
omega = 2 * math.pi / 5060.0  # the source's period, so that omega t = 4 pi at 10,120 s
gravity = omega**2 * radius
speed = 0.5 * MILE  # m/s

sources = {  # Problem 3's error sizes in SI
    "tilt": ("level misalignment 0.01°", math.radians(0.01)),
    "velocity": ("launch velocity 1 ft/s", 1 * FOOT),
    "accelerometer": ("accelerometer 1e-4 g", 1e-4 * gravity),
    "drift": ("gyro drift 0.01°/h", math.radians(0.01) / 3600),
    "azimuth": ("azimuth 0.01°", math.radians(0.01)),
}
t = np.linspace(0.0, 10_120.0, 500)
t_dots = np.linspace(0.0, 10_120.0, 15)

fig, grid = plt.subplots(2, 3, figsize=(11, 6.5), layout="constrained")
axes = grid.flat
for ax, (source, (label, size)) in zip(axes, sources.items()):
    ax.plot(t / 60, flat_error(source, size, t, gravity, speed) / FOOT, "--", label="flat Earth")
    ax.plot(t / 60, spherical_error(source, size, t, radius, gravity, speed) / FOOT, label="spherical (Schuler)")
    simulated = simulate_error(source, size, t_dots, radius, gravity, speed)
    ax.plot(t_dots / 60, simulated / FOOT, "o", ms=3, label="simulated")
    ax.set_title(label, fontsize=10)
    ax.set_xlabel("time, min")
    ax.set_ylabel("position error, ft")
grid[1, 2].legend(*grid[0, 0].get_legend_handles_labels(), loc="center")
grid[1, 2].axis("off")
plt.show()

# %%
# At the end of the flight (omega t = 4 pi) every Schuler oscillation is back at
# zero, while the drift error has grown to R epsilon t:
end = np.array([10_120.0])
for source, (label, size) in sources.items():
    flat = flat_error(source, size, end, gravity, speed)[0] / FOOT
    sphere = spherical_error(source, size, end, radius, gravity, speed)[0] / FOOT
    print(f"{label:28s} flat {round(flat):12,d} ft   spherical {round(sphere):8,d} ft")

# %%
# One source through the system, as ``schuler errors run`` runs it: the result
# holds the outputs, the error histories (the CSV of ``--out``) and its figure.
run = schuler.get_system("errors").run(source="drift", earth="bollay")
print(f"largest spherical error {run.max_spherical_m / FOOT:,.0f} ft, Schuler period {run.schuler_period_s:.0f} s")
print(run.to_dataframe().iloc[::250])
run.plot()
plt.show()

# %%
# The same table with the printed values and the source's errata:
# ``schuler errors reproduce``; the curves as figures: ``schuler errors plot --out results/errors``.
