"""The command line of every system, generated from its :class:`~schuler.contract.System`.

``schuler NAME run [SCENARIO.toml]`` (the system's parameters, ``--monte-carlo``,
``--seed``, ``--fidelity`` where offered, ``--imu`` where the IMU layer maps to
the system: :mod:`schuler.imu.instrument`; a scenario of the system sets what the
options do not), ``schuler NAME sweep SCENARIO.toml`` (:mod:`schuler.cli.sweep`
for the system's scenarios), ``schuler NAME reproduce`` and the system's own
actions: each parses its options with the system's
:class:`~schuler.params.ParameterSet`, calls one function of the system and
hands the result to :func:`~schuler.cli.common.emit`. No numerics here.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path

import click

from schuler.cli.common import (
    emit,
    json_option,
    options_named,
    out_option,
    parameter_options,
    progress_reporter,
)
from schuler.cli.sweep import scenario_of, sweep_command
from schuler.contract import RUN_OPTIONS, Action, System
from schuler.exceptions import InvalidParameter
from schuler.imu.instrument import apply_instrument, instrument_options
from schuler.memory import format_seconds, no_time_limit
from schuler.params import Case, ParameterSet

_CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}

NO_TIME_LIMIT = click.Option(["--no-time-limit"], is_flag=True, default=False,
                             help="Run even when the work is estimated to take longer than the time budget "
                                  "(10 min, or SCHULER_TIME_BUDGET).")
"""The option that accepts work estimated past the time budget (:func:`schuler.memory.require_time`)."""

WORKERS = click.Option(["--workers"], type=click.IntRange(min=1), default=1, metavar="N", show_default=True,
                       help="Processes evaluating the --monte-carlo members, sharing the cores (1: this process); "
                            "the statistics do not depend on it.")
"""The option that spreads a run's Monte Carlo over local processes (:mod:`schuler.study.executors`)."""


def system_group(system: System) -> click.Group:
    """The click group ``schuler NAME`` with ``run``, ``reproduce`` and the system's actions."""
    group = click.Group(
        name=system.name,
        help=f"{system.title}.\n\nSource: {system.reference.rstrip('.')}."
        + (f"\n\nGuide: docs/_build/html/guide/{system.guide}.html (make docs)" if system.guide else ""),
        short_help=system.title + ".",
        context_settings=_CONTEXT,
    )
    group.add_command(_run_command(system))
    group.add_command(sweep_command(system.name))
    group.add_command(_reproduce_command(system))
    for action in system.actions:
        group.add_command(_action_command(system, action))
    return group


def _given(case) -> dict:
    """The values the user set (defaults stay to the system, so option conflicts are judged on what was typed)."""
    return {name: case[name] for name in case.given}


def execute_run(system: System, case: Case, *, monte_carlo: int, seed: int, fidelity: str | None,
                out_dir: Path | None, as_json: bool, draw=None, instrument: Case | None = None,
                time_limit: bool = True, workers: int = 1) -> None:
    """What ``schuler NAME run`` and ``schuler run SCENARIO`` do with a parsed case.

    ``instrument``: the ``--imu`` options that set part of the case (shown in the JSON inputs);
    ``time_limit``: False for ``--no-time-limit`` (work longer than the time budget accepted);
    ``workers``: processes for the Monte Carlo's members (``--workers``).
    """
    from schuler.study.executors import make_executor

    with options_named(system.parameters + RUN_OPTIONS), no_time_limit(not time_limit):
        estimate = system.work_seconds(case, monte_carlo, workers=workers)
        label = f"{system.name} Monte Carlo" + (f" (estimate {format_seconds(estimate)})" if estimate else "")
        executor = make_executor(workers=workers) if monte_carlo and workers > 1 else None
        finished = False
        try:
            with progress_reporter(label, enabled=not as_json) as progress:
                result = system.run(monte_carlo=monte_carlo, seed=seed, fidelity=fidelity, progress=progress,
                                    draw=draw, executor=executor, **_given(case))
            finished = True
        finally:
            if executor is not None:
                executor.close(abort=not finished)
    files = _write_files(system.write, result, out_dir, f"{system.name} run")
    inputs = dict(case)
    parameters = system.parameters
    if instrument is not None:
        inputs.update({name: instrument[name] for name in instrument.given})
        parameters = parameters + instrument_options(system.name)
    if monte_carlo:
        inputs.update(monte_carlo=monte_carlo, seed=seed)
    if system.fidelities:
        inputs["fidelity"] = system.check_fidelity(fidelity)
    emit(result, as_json, inputs=inputs, parameters=parameters, files=files)


def _write_files(writer, result, out_dir: Path | None, command: str) -> list:
    """The run's files in ``out_dir`` as one set, complete or absent (:func:`schuler.io.write_file_set`)."""
    from schuler.io import write_file_set

    return write_file_set(out_dir, lambda folder: writer(result, folder), command) if out_dir is not None else []


def _with_instrument(system: System, case: Case, options: Case) -> tuple[Case, Case | None]:
    """The case with the IMU's values where the user set none (``--imu``); the options if they were used."""
    if not options.given:
        return case, None
    if "imu" not in options.given:
        extra = sorted(options.given)[0]
        raise InvalidParameter("--" + extra.replace("_", "-"), "applies with --imu only")
    with options_named(system.parameters + instrument_options(system.name)):
        case, _ = apply_instrument(system.name, system.parameters, case, options["imu"],
                                   window=options.get("imu_window"), latitude=options.get("imu_latitude"))
    return case, options


def _over_scenario(system: System, loaded, case: Case, *, replace_instrument: bool) -> Case:
    """The scenario's values with the options the user typed in their place.

    A typed option also displaces the file's values it excludes (the system's
    exclusive groups); with ``--imu`` typed, the file's ``[instrument]`` is
    dropped (its values stand only where neither the file nor the options set one).
    """
    typed = _given(case)
    base = system.parameters.parse(loaded.written) if replace_instrument else loaded.values
    displaced = {name for group in system.parameters.exclusive if typed.keys() & set(group) for name in group}
    kept = {name: base[name] for name in base.given if name not in typed and name not in displaced}
    return system.parameters.case({**kept, **typed})


def _run_command(system: System) -> click.Command:
    run_options = ParameterSet(RUN_OPTIONS, owner=system.name)
    instrument = instrument_options(system.name)  # --imu where the IMU layer maps to the system

    def run(scenario: Path | None, out_dir: Path | None, as_json: bool, no_time_limit: bool, workers: int = 1,
            fidelity: str | None = None, **raw):
        options = run_options.parse({k: raw.pop(k) for k in run_options.names}, labels="option")
        imu_options = instrument.parse({k: raw.pop(k) for k in instrument.names}, labels="option")
        case = system.parameters.parse(raw, labels="option")
        draw = None
        if scenario is not None:
            loaded = scenario_of(scenario, system.name)
            case = _over_scenario(system, loaded, case, replace_instrument="imu" in imu_options.given)
            table = loaded.monte_carlo
            from_file = {"monte_carlo": table.cases, "seed": table.seed} if table is not None else {}
            options = run_options.case({**from_file, **_given(options)})
            draw = loaded.draw if options["monte_carlo"] else None
            fidelity = fidelity or loaded.fidelity
            out_dir = out_dir or loaded.out_dir
            as_json = as_json or loaded.as_json
        case, used = _with_instrument(system, case, imu_options)
        execute_run(system, case, monte_carlo=options["monte_carlo"], seed=options["seed"], fidelity=fidelity,
                    out_dir=out_dir, as_json=as_json, draw=draw, instrument=used, time_limit=not no_time_limit,
                    workers=workers)

    command = click.Command("run", callback=run, context_settings=_CONTEXT,
                            help=f"One case: {system.title}. The headline numbers; figures and data with --out.\n\n"
                                 "Bare numbers are in each option's display unit (shown below); values with "
                                 "units are converted. --monte-carlo N adds N random members around the case.\n\n"
                                 f"With SCENARIO.toml (a scenario of {system.name}), the options set here win over "
                                 "the file's values; without options, the result is that of schuler run SCENARIO.toml.")
    command.params.append(click.Argument(["scenario"], required=False, metavar="[SCENARIO.toml]",
                                         type=click.Path(dir_okay=False, path_type=Path)))
    decorated = parameter_options(system.parameters + RUN_OPTIONS + instrument)(command.callback)
    for param in reversed(getattr(decorated, "__click_params__", [])):
        command.params.append(param)
    if system.fidelities:
        command.params.append(click.Option(
            ["--fidelity"], type=click.Choice(system.fidelities), default=None,
            help=f"How outputs are computed: {', '.join(system.fidelities)}. [default: {system.fidelities[0]}]"))
    command.params.extend([WORKERS, NO_TIME_LIMIT])
    command.params.extend(_output_params())
    return command


def _output_params() -> list[click.Parameter]:
    # the shared options, as click collects them into a command (in the order declared)
    return click.command()(out_option(json_option(lambda **kw: None))).params


def _reproduce_command(system: System) -> click.Command:
    def reproduce(out_dir: Path | None, as_json: bool, **raw):
        case = system.reproduce_parameters.parse(raw, labels="option")
        with options_named(system.reproduce_parameters):
            result = system.reproduce(**case)
        files = _write_files(system.write, result, out_dir, f"{system.name} reproduce")
        emit(result, as_json, inputs=dict(case), parameters=system.reproduce_parameters, files=files)

    return _command("reproduce", reproduce, system.reproduce_parameters,
                    f"The source's published case, printed beside the computed values.\n\nSource: {system.reference}.")


def _action_command(system: System, action: Action) -> click.Command:
    paths = [argument.name for argument in action.arguments] + (["output"] if action.output_file else [])

    def act(out_dir: Path | None, as_json: bool, **raw):
        files_in = {name: raw.pop(name) for name in paths}
        case = action.parameters.parse(raw, labels="option")
        with options_named(action.parameters, names=("output",) if action.output_file else ()):
            result = action.function(**files_in, **case)
        files = _write_files(partial(system.write, action=action.name), result, out_dir,
                             f"{system.name} {action.name}")
        written = getattr(result, "files", None) or []
        emit(result, as_json, inputs={**{k: str(v) for k, v in files_in.items()}, **case},
             parameters=action.parameters, files=[*written, *files])

    command = _command(action.name, act, action.parameters, action.help)
    for argument in reversed(action.arguments):
        command.params.insert(0, click.Argument([argument.name], metavar=argument.metavar,
                                                type=click.Path(dir_okay=False, path_type=Path)))
    if action.output_file:
        command.params.insert(len(action.arguments), click.Option(
            ["--output", "-o", "output"], required=True, type=click.Path(dir_okay=False, path_type=Path),
            help=action.output_file))
    return command


def _command(name: str, callback, parameters: ParameterSet, help_text: str) -> click.Command:
    command = click.Command(name, callback=callback, help=help_text, context_settings=_CONTEXT)
    decorated = parameter_options(parameters)(lambda **kw: None)
    command.params.extend(reversed(getattr(decorated, "__click_params__", [])))
    command.params.extend(_output_params())
    return command
