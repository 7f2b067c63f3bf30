"""The system contract, checked over every registered system with no escape hatch.

Unknown names are refused (with the intended name suggested) at every entry
point; defaults are the same through the API, a scenario file and the command
line; ``run`` gives exactly what ``evaluate`` gives for the same case; random
draws do not depend on chunking or executor; every JSON output carries units.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest

import schuler
from schuler.contract import Cases, System, monte_carlo
from schuler.core.random import RandomStreams
from schuler.exceptions import InvalidParameter, ScenarioError
from schuler.registry import SYSTEM_MODULES, get_system
from schuler.study.scenario import parse_scenario
from schuler.study.sweep import run_sweep

NAMES = list(SYSTEM_MODULES)

MISSPELT = {"errors": ("magnitud", "magnitude"), "vertical": ("latitud", "latitude"),
            "calibrate": ("latitud", "latitude"), "align": ("latitud", "latitude"), "north": ("latitud", "latitude"),
            "imu": ("latitud", "latitude"), "navigate": ("latitud", "latitude"),
            "mission": ("alignement", "alignment"), "aided": ("duraton", "duration")}
"""A misspelt parameter of each system and the name it must suggest (issue 11)."""

LIGHT = {
    "errors": {"duration": 3600.0, "output_step": 60.0},
    "vertical": {"duration": 3 * 3600.0, "output_step": 60.0},
    "calibrate": {},
    "align": {"duration": 600.0},
    "north": {"duration": 600.0, "readout_noise": math.radians(1 / 3600)},
    "imu": {"duration": 120.0},
    "navigate": {"duration": 600.0, "imu_rate": 10.0, "output_step": 60.0, "velocity_error_north": 0.1,
                 "sigma_gyro_bias": 1e-7},
    "mission": {"duration": 1200.0, "output_step": 600.0, "imu_rate": 0.5},
    "aided": {"duration": 300.0, "imu_rate": 20.0, "outage_start": 120.0, "outage_duration": 30.0},
}
"""SI values that keep a system's default case quick (short durations)."""

VARIATIONS = {
    "errors": [{"source": "accelerometer"}, {"source": "azimuth", "speed": 200.0}],
    "vertical": [{"latitude": math.radians(30.0)}, {"speed": 20.0}],
    "calibrate": [{"latitude": math.radians(40.0), "azimuth": math.radians(200.0)}],
    "align": [{"latitude": math.radians(20.0), "drift_east": 1e-7}, {"model": "simplified", "azimuth": 1.0}],
    "north": [{"latitude": math.radians(30.0)}],
    "imu": [{"imu": "industrial", "azimuth": 1.0}, {"imu_rate": 200.0, "latitude": math.radians(-30.0)}],
    "navigate": [{"mode": "platform", "heading_error": 1e-3, "vertical_channel": "free"},
                 {"trajectory": "great-circle", "speed": 200.0, "heading": 1.0, "gyro_bias_x": 1e-7,
                  "imu": "tactical"}],
    "aided": [{"aiding": "gnss-position", "gnss_rate": 2.0}, {"lever_arm_x": 1.0, "imu": "industrial"}],
    "mission": [{"imu": "navigation", "trajectory": "stationary"},
                {"alignment": "gyrocompass", "calibration": "multi-position", "alignment_duration": 600.0}],
}
"""Further cases per system on which run and evaluate must agree."""

UNIT_SUFFIX = re.compile(r"_(rad|rad_s|rad_s2|m|m_s|m_s2|s|hz|deg|rad_sqrt_s|m_s_sqrt_s|s_count)$")


def light(name: str) -> dict:
    system = get_system(name)
    return {k: v for k, v in LIGHT[name].items() if k in system.parameters}


def cases_of(name: str) -> list[dict]:
    base = light(name)
    system = get_system(name)
    variations = [{k: v for k, v in extra.items() if k in system.parameters} for extra in VARIATIONS[name]]
    return [base] + [{**base, **extra} for extra in variations]


def same(a, b, rel=1e-9) -> bool:
    if a is None or b is None or (isinstance(a, float) and math.isnan(a)) or (isinstance(b, float) and math.isnan(b)):
        return (a is None or math.isnan(a)) and (b is None or math.isnan(b))
    return math.isclose(float(a), float(b), rel_tol=rel, abs_tol=1e-300) or (math.isinf(a) and a == b)


def test_get_system_is_top_level_and_suggests():
    assert schuler.get_system("align").name == "align"
    with pytest.raises(InvalidParameter, match="did you mean 'align'"):
        schuler.get_system("allign")


def test_the_command_line_lists_every_system_from_the_registry():
    from click.testing import CliRunner

    from schuler.cli import cli
    from schuler.registry import SUMMARIES

    assert cli.list_commands(None)[:len(NAMES)] == NAMES
    shown = CliRunner().invoke(cli, ["--help"]).output
    assert all(f"{name}" in shown and SUMMARIES[name] in shown for name in NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_declaration_is_complete(name):
    system = get_system(name)
    assert isinstance(system, System) and system.name == name
    assert system.reference and system.title and system.outputs
    assert len({o.name for o in system.outputs}) == len(system.outputs)
    for parameter in system.parameters:
        assert parameter.help.strip(), f"{parameter.name} has no help"
        if parameter.default is not None:
            parameter.parse(parameter.default)
    for output in system.outputs:
        assert output.unit and output.description, output.name


@pytest.mark.parametrize("name", NAMES)
def test_unknown_names_are_refused_everywhere_with_a_suggestion(name, run_cli, tmp_path):
    system = get_system(name)
    wrong, right = MISSPELT[name]
    with pytest.raises(InvalidParameter, match=f"{wrong}: unknown parameter of {name}; did you mean '{right}'"):
        system.run(**{wrong: 1.0})
    with pytest.raises(InvalidParameter, match=f"did you mean '{right}'"):
        system.evaluate_values({wrong: np.ones(2)})
    with pytest.raises(ScenarioError, match=f"{wrong}: unknown key; did you mean '{right}'"):
        parse_scenario(f'system = "{name}"\n[parameters]\n{wrong} = 1\n')
    out = run_cli(name, "run", f"--{wrong}", "1")
    assert out.code == 2 and f"--{right}" in out.stderr
    path = tmp_path / "s.toml"
    path.write_text(f'system = "{name}"\n')
    out = run_cli("sweep", path, "--param", f"{wrong}=1,2", "--out", tmp_path / "o")
    assert out.code == 2 and "unknown parameter" in out.stderr


@pytest.mark.parametrize("name", NAMES)
def test_defaults_are_the_same_through_api_scenario_and_cli(name, run_cli):
    system = get_system(name)
    api = dict(system.case())
    scenario = dict(parse_scenario(f'system = "{name}"\n').values)
    assert scenario == api
    monkey = system.parameters.case()
    assert dict(monkey) == api


@pytest.mark.parametrize("name", NAMES)
def test_run_equals_evaluate_per_case(name):
    system = get_system(name)
    for given in cases_of(name):
        for fidelity in system.fidelities or (None,):
            result = system.run(fidelity=fidelity, **given).to_dict()
            # a system whose run is a realisation gives member 0 of seed 0
            random = RandomStreams(0) if system.realisation else None
            batch = system.evaluate_values({k: np.array([v]) for k, v in given.items()}, fidelity=fidelity,
                                           members=np.array([0]), random=random)
            for output in system.outputs:
                assert output.name in result, f"{name}: run's result lacks output {output.name}"
                assert same(result[output.name], batch[output.name][0]), \
                    (name, fidelity, given, output.name, result[output.name], batch[output.name][0])


@pytest.mark.parametrize("name", [n for n in NAMES if n != "errors"])
def test_monte_carlo_draws_do_not_depend_on_chunking(name):
    system = get_system(name)
    if not system.random_terms:
        pytest.skip(f"{name} has no random terms of its own")
    case = system.case(**light(name))
    small = monte_carlo(system.evaluate, system.outputs, case, 6, RandomStreams(5), chunk=2)
    large = monte_carlo(system.evaluate, system.outputs, case, 6, RandomStreams(5), chunk=6)
    for output, values in small.samples.items():
        np.testing.assert_allclose(values, large.samples[output], rtol=1e-12, atol=0, err_msg=output)
    assert any(np.ptp(values) > 0 for values in small.samples.values()), "the members drew nothing"


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_sweep_draws_do_not_depend_on_chunking_or_executor(name, tmp_path):
    system = get_system(name)
    numeric = next(p for p in system.parameters if p.kind == "quantity" and p.name not in LIGHT[name]
                   and p.default is not None and p.name != "latitude")
    lines = [f'system = "{name}"', "[parameters]"]
    lines += [f'{key} = "{value!r} {system.parameters[key].si_unit}"'
              for key, value in LIGHT[name].items() if key in system.parameters and key not in ("duration",)]
    lines += ["[monte_carlo]", "seed = 3", "[monte_carlo.uniform]", f"{numeric.name} = [{_range(numeric)}]"]
    scenario = parse_scenario("\n".join(lines) + "\n")
    args = dict(monte_carlo=4, progress=False, plots=False)
    if "duration" in LIGHT[name]:
        args["params"] = (f"duration={LIGHT[name]['duration']}",)
    run_sweep(scenario, tmp_path / "a", chunk_size=3, **args)
    run_sweep(scenario, tmp_path / "b", chunk_size=8, workers=2, **args)
    a, b = (pd.read_parquet(tmp_path / d / "results.parquet") for d in "ab")
    pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-12)


def _range(parameter) -> str:
    default = float(parameter.parse(parameter.default))
    from schuler.units import to_unit

    shown = float(to_unit(default, parameter.unit)) if parameter.unit else default
    low, high = (shown * 0.9, shown * 1.1) if shown else (0.0, 1.0)
    if parameter.minimum is not None:
        low = max(low, parameter.minimum + (1e-6 if parameter.exclusive_minimum else 0))
    if parameter.maximum is not None:
        high = min(high, parameter.maximum - (1e-6 if parameter.exclusive_maximum else 0))
    return f"{low!r}, {high!r}"


def _unitless_numbers(data, units, path=""):
    """Numeric leaves whose key has no unit suffix and no entry in ``units``."""
    missing = []
    if isinstance(data, dict):
        for key, value in data.items():
            if key == "units":
                continue
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                if not UNIT_SUFFIX.search(key) and key not in units:
                    missing.append(f"{path}{key}")
            elif isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value if v is not None):
                if not UNIT_SUFFIX.search(key) and key not in units:
                    missing.append(f"{path}{key}")
            else:
                missing += _unitless_numbers(value, units, f"{path}{key}.")
    elif isinstance(data, list):
        for item in data:
            missing += _unitless_numbers(item, units, path)
    return missing


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("action", ["run", "reproduce"])
def test_json_carries_units_for_every_number(name, action, run_cli):
    args = [name, action, "--json"]
    if action == "run":
        for key, value in light(name).items():
            parameter = get_system(name).parameters[key]
            args += [parameter.option, f"{value!r} {parameter.si_unit}" if parameter.si_unit != "1" else repr(value)]
    out = run_cli(*args)
    assert out.code == 0, out.stderr
    data = out.json()
    assert data["schuler_version"] == schuler.__version__ and "inputs" in data
    missing = _unitless_numbers(data, data["units"])
    assert not missing, f"numbers without a unit: {missing}"


@pytest.mark.parametrize("name", NAMES)
def test_reproductions_have_computed_verdicts(name):
    system = get_system(name)
    reproduction = system.reproduce()
    assert reproduction.rows and not reproduction.failures
    for row in reproduction.rows:
        assert row.verdict.startswith(("agrees within", "tuned to match within", "erratum", "not printed")), row
        assert (row.printed is None) == (row.verdict == "not printed in the source")
        if row.verdict == "erratum":
            assert row.note, f"{row.quantity}: an erratum must be explained"


def test_cases_groups_and_member_numbers():
    cases = Cases({"a": np.array([1.0, 2.0, 1.0]), "b": np.array(["x", "y", "x"], dtype=object)},
                  members=np.array([10, 11, 12]))
    groups = [(index.tolist(), sub.members.tolist()) for index, sub in cases.groups("a", "b")]
    assert groups == [([0, 2], [10, 12]), ([1], [11])]
    assert cases.case(1)["b"] == "y"
