"""Naming rules of ``docs/conventions.md`` held over the whole package (one name per thing)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
from collections import defaultdict
from pathlib import Path

import pytest
from click.testing import CliRunner

import schuler
from schuler.cli import cli
from schuler.registry import SYSTEM_MODULES, get_system

PACKAGE = Path(schuler.__file__).parent
MODULES = sorted(info.name for info in pkgutil.walk_packages(schuler.__path__, "schuler."))
NUMBERED = re.compile(r"\b[Ss]ystems? [1-9]\b|\b[Ii]ssue [0-9]+")
"""The project's internal numbering: users know systems by name and never see our issue tracker."""


def defined_twice(namespaces) -> dict[str, list[str]]:
    """Public class names defined in more than one of ``namespaces`` ((module name, namespace) pairs)."""
    owners = defaultdict(list)
    for module, namespace in namespaces:
        for name, value in namespace.items():
            if inspect.isclass(value) and value.__module__ == module and not name.startswith("_"):
                owners[name].append(module)
    return {name: places for name, places in owners.items() if len(places) > 1}


def test_every_public_class_is_defined_once():
    assert len(MODULES) > 100
    assert not defined_twice((name, vars(importlib.import_module(name))) for name in MODULES)


def test_the_rule_finds_a_class_defined_twice():
    made = {module: {"SensorErrors": type("SensorErrors", (), {"__module__": module})} for module in ("a", "b")}
    assert defined_twice(made.items()) == {"SensorErrors": ["a", "b"]}


def test_no_system_or_issue_numbers_in_the_package_text():
    found = []
    for path in sorted(PACKAGE.rglob("*")):
        if path.suffix not in (".py", ".toml", ".html", ".js", ".css", ".md") or "__pycache__" in path.parts:
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if NUMBERED.search(line):
                found.append(f"{path.relative_to(PACKAGE)}:{number}: {line.strip()}")
    assert not found, "\n".join(found)
    assert NUMBERED.search("the ground gyrocompass (system 5)") and NUMBERED.search("issue 18: shares")


@pytest.mark.parametrize("name", sorted(SYSTEM_MODULES))
def test_no_system_or_issue_numbers_in_the_help(name):
    system = get_system(name)
    commands = ["run", "reproduce", *(action.name for action in system.actions)]
    runner = CliRunner()
    for command in commands:
        out = runner.invoke(cli, [name, command, "--help"])
        assert out.exit_code == 0, out.output
        assert not NUMBERED.search(out.output), (command, NUMBERED.search(out.output))


OPTION = re.compile(r"(?<![\w`-])--[a-z][a-z0-9-]*")
"""A command-line option written out (``--imu-rate``); the library quotes the parameter instead (`imu_rate`)."""


def options_in_messages(source: str) -> list[tuple[int, str]]:
    """Options named in the messages of a module's source: the text of every raised exception and the hint of
    every memory and time check (``require``, ``require_time``), with their line numbers."""
    import ast

    found = []
    for node in ast.walk(ast.parse(source)):
        parts = [node.exc] if isinstance(node, ast.Raise) and node.exc is not None else []
        if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) in (
                "require", "require_time"):
            parts.extend(node.args[2:])
        for part in parts:
            for text in ast.walk(part):
                if isinstance(text, ast.Constant) and isinstance(text.value, str):
                    found.extend((text.lineno, option) for option in OPTION.findall(text.value))
    return found


def test_the_library_speaks_of_parameters_and_the_command_line_of_options(run_cli):
    found = [f"{path.relative_to(PACKAGE)}:{line}: {option}" for path in sorted(PACKAGE.rglob("*.py"))
             if "cli" not in path.relative_to(PACKAGE).parts
             for line, option in options_in_messages(path.read_text(encoding="utf-8"))]
    assert not found, "\n".join(found)
    assert options_in_messages('raise ValueError("give --record FILE")\nrequire(1, "x", "--duration")') == [
        (1, "--record"), (2, "--duration")]
    # the command line shows each quoted parameter as its option, the API keeps the parameter's name
    with pytest.raises(schuler.exceptions.InvalidParameter, match="sets its own: `city_speed`, `road_speed`"):
        get_system("aided").run(speed=30.0)
    out = run_cli("aided", "run", "--speed", "30")
    assert out.code == 2 and "sets its own: --city-speed, --road-speed" in out.stderr and "`" not in out.stderr


IMU_SYNONYMS = ("grade", "spec", "imu_spec", "instrument", "imu_grade")
"""Former names of the IMU: each system's IMU is one parameter, ``imu`` (a grade, a spec sheet or a recording)."""


def test_one_imu_name_and_one_trajectory_vocabulary_on_every_system():
    from schuler.navigate.evaluation import TRAJECTORIES

    for name in sorted(SYSTEM_MODULES):
        parameters = get_system(name).parameters
        names = {parameter.name for parameter in parameters}
        assert not names & set(IMU_SYNONYMS), name
        assert all(parameters.renamed[old] == "imu" for old in set(parameters.renamed) & set(IMU_SYNONYMS)), name
        trajectory = next((parameter for parameter in parameters if parameter.name == "trajectory"), None)
        if trajectory is not None and trajectory.kind == "choice":
            # a geodesic is navigate's great-circle wherever it is offered; navigate's names mean its paths
            assert "great-circle" in trajectory.choices and "cruise" not in trajectory.choices, name
    mission = get_system("mission").parameters
    assert set(TRAJECTORIES) <= set(next(p for p in mission if p.name == "trajectory").choices)


DISPLAY_SUFFIX = re.compile(r"_(deg|arcsec|arcmin|deg_h|deg_s|deg_rt_h|mg|ug|ppm|mrad|urad|km|ft|nmi|percent)(_std)?$")
"""Display units as the end of a field's name: a result holds SI (``north_rad``), its table shows deg or arcsec."""


def test_no_result_field_holds_a_display_unit():
    import dataclasses

    found = [f"{name}.{cls.__name__}.{field.name}" for name in MODULES
             for cls in vars(importlib.import_module(name)).values()
             if inspect.isclass(cls) and cls.__module__ == name and dataclasses.is_dataclass(cls)
             for field in dataclasses.fields(cls) if DISPLAY_SUFFIX.search(field.name)]
    assert not found, "\n".join(found)
    assert DISPLAY_SUFFIX.search("north_std_arcsec") and DISPLAY_SUFFIX.search("drift_deg_h")
    assert not DISPLAY_SUFFIX.search("north_std_rad") and not DISPLAY_SUFFIX.search("omega_h")


UNIT_SUFFIX = re.compile(r"_(s|s2|rad|rad_s|deg|deg_h|arcsec|m|m_s|m_s2|hz|ppm|per_s)$")
"""A unit at the end of an argument's name: options are SI and say their unit in the docstring (``duration``)."""


def options_with_a_unit_suffix(namespaces) -> list[str]:
    """``module.function(argument)`` for every option of a public function or method whose name ends in a unit.

    An option is an argument with a default or a keyword-only one; data passed by position keep the name of the
    column they are (``t_s``), and a dataclass's own ``__init__`` takes its fields, which are results.
    """
    found = []
    for module, namespace in namespaces:
        callables = []
        for name, value in namespace.items():
            if name.startswith("_") or getattr(value, "__module__", None) != module:
                continue
            if inspect.isfunction(value):
                callables.append((name, value))
            elif inspect.isclass(value):
                for method_name, method in vars(value).items():
                    method = getattr(method, "__func__", method)
                    record_init = method_name == "__init__" and "__dataclass_fields__" in vars(value)
                    public = not method_name.startswith("_") or method_name == "__init__"
                    if inspect.isfunction(method) and public and not record_init:
                        callables.append((f"{name}.{method_name}", method))
        for name, function in callables:
            for argument in inspect.signature(function).parameters.values():
                option = argument.kind is argument.KEYWORD_ONLY or argument.default is not argument.empty
                if option and UNIT_SUFFIX.search(argument.name):
                    found.append(f"{module}.{name}({argument.name})")
    return found


def test_no_option_of_a_public_function_carries_a_unit_suffix():
    assert not options_with_a_unit_suffix((name, vars(importlib.import_module(name))) for name in MODULES)


def test_the_rule_finds_a_suffixed_option_and_its_former_name_is_refused():
    def hold(t_s, *, duration_s=1.0):
        return t_s, duration_s

    hold.__module__ = "a"
    assert options_with_a_unit_suffix([("a", {"hold": hold})]) == ["a.hold(duration_s)"]
    from schuler.alignment.kalman import KalmanTuning
    from schuler.exceptions import InvalidParameter
    from schuler.imu.spec import preset

    with pytest.raises(InvalidParameter, match="window_s: renamed to 'window'"):
        KalmanTuning.from_model(preset("tactical"), window_s=600.0)
