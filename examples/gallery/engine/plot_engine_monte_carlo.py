"""
A Schuler channel, exactly: one member and a thousand
=====================================================

The engine propagates x' = A x + B u by the matrix exponential (zero-order
hold), exact on any time grid and for batches of members, each with its own
initial state and inputs. Here the single horizontal channel of an INS,
Δx'' + (g/R) Δx = Δa, driven by an accelerometer bias: one member against
the closed form k R (1 − cos ω t), then 1,000 members with random biases and
initial tilts whose statistics are streamed (no member's history is kept).
"""

import matplotlib.pyplot as plt
import numpy as np

from schuler.core.earth import DEFAULT
from schuler.core.lti import StateSpace, simulate, simulate_statistics
from schuler.core.random import RandomStreams

R, g = DEFAULT.radius, DEFAULT.gravity
w = DEFAULT.schuler_frequency  # sqrt(g / R), rad/s
channel = StateSpace([[0, 1], [-(w**2), 0]], [[0], [1]], states=("x", "v"), inputs=("bias",),
                     state_units=("m", "m/s"))
time = np.arange(0.0, 6 * 3600 + 1, 60.0)

bias = 1e-4 * g  # 100 ug
one = simulate(channel, time, inputs=[bias])
closed = bias / w**2 * (1 - np.cos(w * time))
print(f"largest difference from the closed form: {np.max(np.abs(one['x'] - closed)):.2e} m "
      f"of {np.max(closed):.0f} m")

# %%
# A thousand members: accelerometer bias 1-sigma 100 ug and an initial
# velocity error of 0.1 m/s, drawn from addressed streams (member k's draws
# depend only on the seed and k).
streams = RandomStreams(2024)
members = np.arange(1000)
biases = 1e-4 * g * streams.normal("bias", members)
initial = np.column_stack([np.zeros(members.size), 0.1 * streams.normal("velocity", members)])
stats = simulate_statistics(channel, time, initial, inputs=biases[:, None])

fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
ax.plot(time / 3600, one["x"] / 1000, label="one member, 100 ug bias")
ax.fill_between(time / 3600, stats.percentile(5, "x") / 1000, stats.percentile(95, "x") / 1000, alpha=0.3,
                label="1,000 members, 5-95 %")
ax.plot(time / 3600, stats.std("x") / 1000, "k--", label="standard deviation")
ax.set(xlabel="time, h", ylabel="position error, km")
ax.legend()
plt.show()
