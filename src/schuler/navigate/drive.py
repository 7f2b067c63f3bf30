"""The ``drive`` trajectory: a car's drive with stops, speed changes and 90-degree turns, on a level road.

:func:`drive` builds a :class:`GroundVehicleProfile`: a :class:`~schuler.navigate.trajectory.WaypointProfile`
(speed and heading blended between waypoints by the quintic smoothstep, so velocity and attitude are C^2 and
the ideal specific force and angular rate continuous) whose roll is zero. A car does not bank into a turn as a
coordinated aircraft does: its lateral acceleration V psi' appears as lateral specific force on body y, and its
pitch follows the road's gradient (the flight-path angle, zero on the default level road).

The drive, deterministic from its parameters: ``stops`` stationary periods of ``stop_duration`` (the first at
the start, the last at the end), and between two consecutive stops one leg:

    accelerate to city_speed -> cruise -> slow to turn_speed -> turn 90 deg -> accelerate to road_speed
    -> cruise -> slow to turn_speed -> turn 90 deg -> accelerate to city_speed -> cruise -> stop.

Speed changes take |dV| / acceleration (the mean rate; the smoothstep's peak is 15/8 of it), at least
:data:`SHORTEST_SPEED_CHANGE_S`; a turn of 90 deg at
turn_speed V and radius R takes (pi / 2) R / V (mean yaw rate V / R, mean lateral acceleration V^2 / R). The
cruises fill the legs to the total duration (city cruises a quarter of a leg's cruising time each, the road
cruise half). Legs turn right, then left, alternately, so the road zigzags north-east from a north start.

Examples
--------
>>> path = drive()
>>> path.duration, [(round(a, 3), round(b, 3)) for a, b in path.stationary_intervals()][:2]
(1500.0, [(0.0, 25.0), (491.667, 516.667)])
>>> float(np.abs(path.kinematics(np.array([10.0, 500.0]))[0]).max())
0.0
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from schuler.core.attitude import quaternion_from_euler
from schuler.exceptions import InvalidParameter
from schuler.navigate.trajectory import WaypointProfile

SHORTEST_SPEED_CHANGE_S = 4.0
"""Shortest speed change, s: a small change at the mean acceleration would jerk (the blend's jerk is
60 dV / T^3; 2 m/s in 4 s is 1.9 m/s^3)."""


@dataclass(frozen=True)
class GroundVehicleProfile(WaypointProfile):
    """A waypoint profile with the roll of a ground vehicle: zero (no banking in turns); see the module.

    Parameters are those of :class:`~schuler.navigate.trajectory.WaypointProfile`.
    """

    def kinematics(self, t):
        """Velocity (n, 3) m/s NED and attitude q_bn (n, 4) at times t (s), roll zero.

        Parameters
        ----------
        t : float or array_like
            Times since the start, s, shape (n,); before the first and after the last waypoint the values hold.

        Returns
        -------
        velocity : ndarray
            Ground velocity, m/s, NED, shape (n, 3).
        quaternion : ndarray
            Attitude q_bn (roll 0, pitch the flight-path angle, heading the course), plain numbers, shape (n, 4).
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        speed, _, _ = self._blend(self.speeds, t)
        psi, _, _ = self._blend(self.headings, t)
        gamma, _, _ = self._blend(self.flight_path_angles, t)
        horizontal = speed * np.cos(gamma)
        velocity = np.stack([horizontal * np.cos(psi), horizontal * np.sin(psi), -speed * np.sin(gamma)], axis=-1)
        return velocity, quaternion_from_euler(np.zeros_like(psi), gamma, psi)



def _positive(name: str, value: float, largest: float) -> float:
    number = float(value)
    if not (math.isfinite(number) and 0.0 < number <= largest):
        raise InvalidParameter(name, f"must lie in (0, {largest:g}], got {value!r}")
    return number


def drive(*, latitude: float = math.radians(30.5), longitude: float = math.radians(114.5), height: float = 20.0,
          heading: float = 0.0, duration: float = 1500.0, stops: int = 4, stop_duration: float = 25.0,
          city_speed: float = 10.0, road_speed: float = 20.0, turn_speed: float = 8.0, turn_radius: float = 40.0,
          acceleration: float = 1.5) -> GroundVehicleProfile:
    """A car-like drive with stops, speed changes and 90-degree turns (see the module for its plan).

    Parameters
    ----------
    latitude, longitude : float
        Start, rad (default 30.5 deg N, 114.5 deg E).
    height : float
        Height of the (level) road above the ellipsoid, m.
    heading : float
        Initial heading, rad clockwise from north.
    duration : float
        Total duration, s.
    stops : int
        Number of stationary periods (>= 2), the first at the start and the last at the end.
    stop_duration : float
        Length of each stop, s.
    city_speed, road_speed, turn_speed : float
        Cruising speeds in town and on the road, and the speed through turns, m/s.
    turn_radius : float
        Mean radius of the 90-degree turns, m.
    acceleration : float
        Mean acceleration and deceleration of speed changes, m/s^2.

    Returns
    -------
    GroundVehicleProfile
        Named "drive".

    Raises
    ------
    InvalidParameter
        A parameter out of range, or a duration too short for the stops, speed changes and turns.
    """
    if isinstance(stops, bool) or not isinstance(stops, int | np.integer) or not 2 <= stops <= 100:
        raise InvalidParameter("stops", f"must be a whole number in [2, 100], got {stops!r}")
    duration = _positive("duration", duration, 1.0e6)
    stop_duration = _positive("stop_duration", stop_duration, 1.0e5)
    speeds = {name: _positive(name, value, 70.0) for name, value in
              (("city_speed", city_speed), ("road_speed", road_speed), ("turn_speed", turn_speed))}
    radius = _positive("turn_radius", turn_radius, 1.0e4)
    mean_acceleration = _positive("acceleration", acceleration, 10.0)
    if not math.isfinite(heading):
        raise InvalidParameter("heading", f"must be finite, got {heading!r}")
    city, road, turn = speeds["city_speed"], speeds["road_speed"], speeds["turn_speed"]
    turn_time = 0.5 * math.pi * radius / turn

    def change(v0: float, v1: float) -> float:
        return max(abs(v1 - v0) / mean_acceleration, SHORTEST_SPEED_CHANGE_S)

    fixed = (change(0, city) + change(city, turn) + 2 * turn_time + change(turn, road) + change(road, turn)
             + change(turn, city) + change(city, 0))
    legs = stops - 1
    cruising = (duration - stops * stop_duration) / legs - fixed
    if cruising <= 0:
        needed = stops * stop_duration + legs * fixed
        raise InvalidParameter("duration", f"{duration:g} s is too short: {stops} stops of {stop_duration:g} s "
                               f"and {legs} legs of speed changes and turns need more than {needed:.1f} s")
    times, values, psis = [0.0], [0.0], [float(heading)]

    def step(length: float, speed: float, turn_angle: float = 0.0) -> None:
        times.append(times[-1] + length)
        values.append(speed)
        psis.append(psis[-1] + turn_angle)

    for leg in range(legs):
        step(stop_duration, 0.0)
        side = 0.5 * math.pi if leg % 2 == 0 else -0.5 * math.pi
        step(change(0, city), city)
        step(0.25 * cruising, city)
        step(change(city, turn), turn)
        step(turn_time, turn, side)
        step(change(turn, road), road)
        step(0.5 * cruising, road)
        step(change(road, turn), turn)
        step(turn_time, turn, side)
        step(change(turn, city), city)
        step(0.25 * cruising, city)
        step(change(city, 0), 0.0)
    step(stop_duration, 0.0)
    times[-1] = duration  # the sum of the pieces, exactly the duration asked for
    return GroundVehicleProfile(latitude=latitude, longitude=longitude, height=height, times=np.array(times),
                                speeds=np.array(values), headings=np.array(psis),
                                flight_path_angles=np.zeros(len(times)), name="drive")
