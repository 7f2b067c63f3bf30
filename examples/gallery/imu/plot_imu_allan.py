"""
A spec sheet, a simulated record, its Allan deviation
=====================================================

The IMU layer turns a data sheet into an error model (:func:`schuler.imu.spec.preset`
holds four grades with their sources), simulates records from it (members
addressed by seed and number, independent of how the record is cut), and
analyses records the IEEE 952 way: the overlapping Allan deviation with its
confidence interval, and the noise terms N (random walk), B (bias
instability), K (rate random walk) fitted to it. Here an industrial-grade MEMS
IMU at rest for one hour at 100 Hz: the identified terms come back close to the
spec sheet's.
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from schuler.imu.allan import allan_deviation
from schuler.imu.noise_terms import identify_terms
from schuler.imu.simulate import simulate_record
from schuler.imu.spec import preset

model = preset("industrial")
record = simulate_record(model, duration=3600.0, sample_interval=0.01, seed=1)
curve = allan_deviation(record.gyro[:, 0], record.sample_interval_s)
terms = identify_terms(curve)

DEG_H = math.radians(1) / 3600
fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
ax.loglog(curve.tau_s, curve.adev / DEG_H, "o", ms=3, label="gyro x, simulated record")
ax.fill_between(curve.tau_s, curve.adev_lower / DEG_H, curve.adev_upper / DEG_H, alpha=0.3, label="68 % interval")
ax.loglog(curve.tau_s, terms.model_adev(curve.tau_s) / DEG_H, label="fitted IEEE 952 terms")
ax.loglog(curve.tau_s, np.sqrt(model.gyro.allan_variance(curve.tau_s, 0)) / DEG_H, "k:", label="the model's own curve")
ax.set(xlabel="averaging time τ, s", ylabel="Allan deviation, deg/h")
ax.legend()
plt.show()

# %%
# The angle random walk N in deg/sqrt(h) and the bias instability B in deg/h,
# identified against the spec sheet:
print(f"N: identified {terms.values['N'] / math.radians(1) * 60:.4f} deg/sqrt(h), "
      f"spec {model.gyro.random_walk[0] / math.radians(1) * 60:.4f} deg/sqrt(h)")
print(f"B: identified {terms.values['B'] / DEG_H:.2f} ± {terms.sigma['B'] / DEG_H:.2f} deg/h, "
      f"spec {model.gyro.bias_instability[0] / DEG_H:.2f} deg/h")

# %%
# The whole record's six channels, their terms and the grade are
# :func:`schuler.imu.allan_deviation` (a record or a file; ``plot()`` draws the
# figures of ``schuler imu allan``) and :func:`schuler.imu.identify`; a round
# trip (simulate -> identify returns what went in) is
# :func:`schuler.imu.characterise.round_trip`.
