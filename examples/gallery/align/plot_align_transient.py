"""
Azimuth alignment transient
===========================

Test.
"""

import math

import matplotlib.pyplot as plt

import schuler

align = schuler.get_system("align")
result = align.run(latitude=math.radians(50), drift_east=math.radians(0.01) / 3600)
print(result)
fig, ax = plt.subplots()
ax.plot([0, 1], [0, 1])
plt.show()
