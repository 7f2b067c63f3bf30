"""The Python API checks what the command line checks, over every registered system.

``System.evaluate_values`` (batches of SI arrays) refuses what ``run`` refuses:
values out of the declared range, NaN (not set is None), booleans, complex
numbers, text where a number is due, empty and multi-dimensional arrays — each
as :class:`~schuler.exceptions.InvalidParameter` naming the parameter, before
any evaluation. A draw of ``run(draw=...)`` is held to the same rules. A new
system in the registry is held to them by the parametrisation alone.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from schuler.exceptions import InvalidParameter
from schuler.registry import SYSTEM_MODULES, get_system
from schuler.units import from_unit

NUMERIC = [(system, parameter.name) for system in SYSTEM_MODULES for parameter in get_system(system).parameters
           if parameter.kind in ("quantity", "integer")]
"""Every numeric parameter of every registered system."""


def _valid_si(parameter) -> float:
    """An SI value inside the parameter's range (its default, else a point of its range)."""
    if parameter.default is not None and not isinstance(parameter.default, str):
        shown = float(parameter.default)
    else:
        low = parameter.minimum if parameter.minimum is not None else -1.0
        high = parameter.maximum if parameter.maximum is not None else low + 2.0
        shown = 0.5 * (low + high)
    return float(shown) if parameter.kind == "integer" else float(from_unit(shown, parameter.unit))


def _out_of_range_si(parameter) -> list[float]:
    """SI values just outside each declared bound (by the bound's size, at least 1 display unit)."""
    values = []
    for bound, sign in ((parameter.minimum, -1.0), (parameter.maximum, 1.0)):
        if bound is not None:
            shown = bound + sign * max(1.0, abs(bound))
            values.append(shown if parameter.kind == "integer" else float(from_unit(shown, parameter.unit)))
    return values


def _refused(system: str, name: str, value) -> InvalidParameter:
    with pytest.raises(InvalidParameter) as caught:
        get_system(system).evaluate_values({name: value})
    return caught.value


@pytest.mark.parametrize(("system", "name"), NUMERIC)
def test_every_numeric_parameter_refuses_bad_values_naming_itself(system, name):
    parameter = get_system(system).parameters[name]
    good = _valid_si(parameter)
    bad = [*_out_of_range_si(parameter), math.nan, math.inf, [good, math.nan], True, np.array([True]), 1 + 1j,
           "not a number", [], [[good, good]], np.zeros((2, 0))]
    for value in bad:
        error = _refused(system, name, value)
        assert error.name == name, (value, str(error))


@pytest.mark.parametrize(("system", "name"), NUMERIC)
def test_bounded_parameters_accept_their_bounds(system, name):
    parameter = get_system(system).parameters[name]
    for bound, exclusive in ((parameter.minimum, parameter.exclusive_minimum),
                             (parameter.maximum, parameter.exclusive_maximum)):
        if bound is None:
            continue
        si = bound if parameter.kind == "integer" else float(from_unit(bound, parameter.unit))
        if exclusive:
            with pytest.raises(InvalidParameter, match=f"^{name}: "):
                parameter.check_array(np.array([si]))
        else:
            checked = parameter.check_array(np.array([si, si]))
            assert float(checked[1]) == pytest.approx(parameter.check(si), rel=1e-12)


@pytest.mark.parametrize(("system", "name", "value"), [
    ("errors", "speed", 1e9), ("errors", "radius", 1e-3), ("errors", "magnitude", -1.0),
    ("align", "azimuth", 1e6), ("align", "time_constant", 1e9), ("align", "damping", 1e9),
    ("mission", "latitude", math.radians(85.0)), ("navigate", "duration", [math.nan]),
])
def test_the_cases_the_command_line_refuses_are_refused(system, name, value):
    with pytest.raises(InvalidParameter, match=f"^{name}: "):
        get_system(system).evaluate_values({name: value})
    with pytest.raises(InvalidParameter, match=f"^{name}: "):
        get_system(system).run(**{name: value if np.ndim(value) == 0 else value[0]})


def test_mission_latitude_limit_is_the_same_in_both_entry_points():
    mission = get_system("mission")
    assert mission.checked_arrays({"latitude": math.radians(80.0)})["latitude"][0] == pytest.approx(
        math.radians(80.0), rel=1e-15)
    with pytest.raises(InvalidParameter, match=r"latitude: 85 deg is outside \[-80, 80\] deg"):
        mission.evaluate_values({"latitude": [math.radians(10.0), math.radians(85.0)]})


def test_choices_and_flags_are_checked_in_batches():
    errors = get_system("errors")
    with pytest.raises(InvalidParameter, match="^source: 'drif' is not one of"):
        errors.evaluate_values({"source": ["drift", "drif"]})
    with pytest.raises(InvalidParameter, match="^preset_integrators: 1.0 is not true or false"):
        get_system("vertical").evaluate_values({"preset_integrators": [1.0]})


def test_none_means_not_set_and_arrays_must_agree_in_length():
    errors = get_system("errors")
    unset = errors.evaluate_values({"radius": None, "source": "tilt"}, fidelity="closed")
    nominal = errors.evaluate_values({"source": "tilt"}, fidelity="closed")
    assert unset["final_flat_m"][0] == pytest.approx(nominal["final_flat_m"][0], rel=1e-15)
    with pytest.raises(InvalidParameter, match="different lengths"):
        errors.evaluate_values({"speed": [1.0, 2.0], "duration": [10.0, 20.0, 30.0]})


def test_exclusive_options_are_refused_by_run_and_ordered_in_a_batch():
    north = get_system("north")
    with pytest.raises(InvalidParameter, match="^latitude: cannot be combined with omega_h"):
        north.run(latitude=math.radians(50.0), omega_h=4.7e-5)
    # a batch may mix cases of either kind: each case's own rule applies (the latitude where it is set)
    mixed = north.checked_arrays({"latitude": [math.radians(50.0), None], "omega_h": [None, 4.7e-5]})
    assert np.isnan(mixed["latitude"][1]) and np.isnan(mixed["omega_h"][0])


def test_a_misspelt_draw_is_refused_with_a_suggestion():
    align = get_system("align")
    with pytest.raises(InvalidParameter, match="^latitud: unknown parameter of align; did you mean 'latitude'"):
        align.run(duration=60.0, monte_carlo=3, draw=lambda m: {"latitud": np.full(m.size, 0.5)})
    with pytest.raises(InvalidParameter, match=r"^latitude: 114.592 deg is outside "):
        align.run(duration=60.0, monte_carlo=3, draw=lambda m: {"latitude": np.full(m.size, 2.0)})
    drawn = align.run(duration=60.0, monte_carlo=3, draw=lambda m: {"latitude": np.full(m.size, 0.5)})
    assert drawn.monte_carlo.members == 3


def test_validation_of_a_million_cases_is_vectorised():
    align = get_system("align")
    values = {"latitude": np.linspace(-1.5, 1.5, 1_000_000), "time_constant": np.full(1_000_000, 30.0)}
    started = time.perf_counter()
    checked = align.checked_arrays(values)
    seconds = time.perf_counter() - started
    assert checked["latitude"].dtype == np.float64
    # about 0.03 s for both arrays (2 x 1e6 values) on the development machine; a per-case loop takes over 20 s
    assert seconds < 2.0


def test_a_batch_with_the_magnitude_unset_parses_each_source_once():
    errors = get_system("errors")
    speeds = np.linspace(1.0, 1000.0, 20_000)
    started = time.perf_counter()
    out = errors.evaluate_values({"speed": speeds, "source": "azimuth"}, fidelity="closed")
    seconds = time.perf_counter() - started
    single = errors.evaluate_values({"speed": speeds[-1], "source": "azimuth"}, fidelity="closed")
    assert out["final_flat_m"][-1] == pytest.approx(single["final_flat_m"][0], rel=1e-12)
    # 3.5 us per case here (0.07 s); parsing the unset magnitude case by case took 400 us per case (8 s)
    assert seconds < 2.0


def test_quantities_may_carry_their_unit_as_text_or_pint():
    from schuler.units import ureg

    align = get_system("align")
    assert align.case(latitude="50 deg")["latitude"] == pytest.approx(math.radians(50.0), rel=1e-12, abs=0)
    assert align.case(latitude=50 * ureg.deg)["latitude"] == pytest.approx(math.radians(50.0), rel=1e-12, abs=0)
    checked = align.checked_arrays({"latitude": np.array([10.0, 20.0]) * ureg.deg, "drift_east": "0.01 deg/h",
                                    "duration": "10 min"})
    assert checked["latitude"] == pytest.approx(np.radians([10.0, 20.0]), rel=1e-12)
    assert checked["drift_east"][0] == pytest.approx(math.radians(0.01) / 3600.0, rel=1e-12)
    assert checked["duration"][0] == 600.0
    by_text = align.evaluate_values({"latitude": ["50 deg"]}, fidelity="closed")
    by_number = align.evaluate_values({"latitude": [math.radians(50.0)]}, fidelity="closed")
    assert by_text["azimuth_error_rad"][0] == by_number["azimuth_error_rad"][0]


@pytest.mark.parametrize(("value", "reason"), [
    ("50", "'50' has no unit: write it with one ('50 deg') or give a number in SI (rad)"),
    ("95 deg", "'95 deg' is outside"),
    ("3 m", "'3 m' is not an angle"),
])
def test_text_without_a_unit_or_of_the_wrong_kind_is_refused(value, reason):
    with pytest.raises(InvalidParameter, match=f"^latitude: {reason}".replace("(", r"\(").replace(")", r"\)")):
        get_system("align").case(latitude=value)


def test_systems_are_listed_and_the_package_help_names_every_one():
    import schuler

    assert schuler.list_systems() == list(SYSTEM_MODULES)
    assert f"{len(SYSTEM_MODULES)} instrument systems" in schuler.__doc__
    for name, module in SYSTEM_MODULES.items():
        assert f"``{name}``  :mod:`{module.rsplit('.', 1)[0]}`" in schuler.__doc__


def test_an_action_is_reached_by_name_and_a_misspelt_one_is_refused():
    north = get_system("north")
    assert north.action("identify") is next(a.function for a in north.actions if a.name == "identify")
    with pytest.raises(InvalidParameter, match="^action: 'identfy' is not an action of north; did you mean "
                                               "'identify'\\? choose from identify"):
        north.action("identfy")
