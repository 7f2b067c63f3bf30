"""
Aided INS: how far a tactical IMU drifts in a GNSS outage
=========================================================

A 10-min drive (stops, turns, town and road speeds) with a tactical IMU at
100 Hz and 1-Hz GNSS positions and velocities, corrected by the 21-state
error-state Kalman filter; GNSS is lost for 60 s every 200 s. Errors are
computed - true in NED; the shaded band is the filter's own +-3-sigma. In each
outage the error grows free-inertially (velocity error, accelerometer bias and
tilt) and the first fix after it pulls the solution back. A Monte Carlo of 16
members gives the drift's spread beside the filter's predicted 1-sigma.
"""

import matplotlib.pyplot as plt

import schuler

aided = schuler.get_system("aided")
result = aided.run(duration="10 min", outage_start="100 s", outage_every="200 s", monte_carlo=16, seed=1)
print(result)

fig = result.plot("aided_errors")
plt.show()

# %%
# Each outage's largest horizontal error against the filter's 1-sigma at its end; the Monte Carlo's statistics
# are typed, one entry per output.
for outage in result.outages:
    print(f"outage at {outage['start_s']:.0f} s: largest {outage['horizontal_error_max_m']:.2f} m, "
          f"filter 1-sigma at its end {outage['horizontal_error_sigma_m']:.2f} m")
spread = result.monte_carlo["outage_horizontal_error_max_m"]
print(f"over {spread.count} members: largest outage error {spread.mean:.2f} m mean, {spread.p95:.2f} m p95")
fig = result.plot("aided_outage_drift")
plt.show()

# %%
# The errors as a table indexed by time (SI units in the column names).
frame = result.to_dataframe()
print(frame[["north_error_m", "east_error_m", "north_sigma_m", "east_sigma_m"]].describe())
