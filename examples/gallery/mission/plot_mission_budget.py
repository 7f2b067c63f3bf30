"""
Mission: the error budget of a navigation-grade INS at rest
===========================================================

A mission calibrates the gyros, aligns, and navigates; every error source that
survives calibration and alignment (biases, scale factors, random walks) is
propagated separately through the WGS-84 psi-angle model, so the final
horizontal position-error variance splits into shares that add up to 1. Here a
navigation-grade IMU sits still for two hours after a 5-min Kalman alignment:
the stacked budget shows which source grows into the error, and when.
"""

import matplotlib.pyplot as plt

import schuler

mission = schuler.get_system("mission")
r = mission.run(imu="navigation", trajectory="stationary", duration=2 * 3600.0, output_step=120.0)
r.plot("mission_budget")
plt.show()

# %%
# The headline numbers (SI) and the shares, largest first; they add up to 1:
print(f"horizontal position error, 1-sigma: {r.position_error_sigma_m:,.0f} m")
print(f"dominant source: {r.dominant_source} ({r.dominant_share:.1%})")
for name, share in sorted(r.budget.items(), key=lambda item: -item[1])[:5]:
    print(f"  {name:22s} {share:7.2%}")
print(f"sum of the shares: {sum(r.budget.values()):.9f}")

# %%
# The example missions run the same way (covariance only in seconds; a Monte
# Carlo of the nonlinear INS beside it with ``--monte-carlo``)::
#
#     schuler run examples/mission_navigation.toml
#     schuler mission run --imu navigation --trajectory great-circle --duration '10 h' --monte-carlo 1000 --json
