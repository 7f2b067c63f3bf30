"""``schuler sweep SCENARIO`` and ``schuler NAME sweep SCENARIO``: one command, with or without its system.

Under a system's group (``schuler mission sweep``) the command is the same
sweep, refusing a scenario of another system; :func:`scenario_of` is that
check, shared with ``schuler NAME run SCENARIO``.
"""

from __future__ import annotations

from pathlib import Path

import click

from schuler.cli.common import FOLDER, emit, folder_not_option, json_option
from schuler.exceptions import ScenarioError

SCENARIO_ARGUMENT = click.argument("scenario", metavar="SCENARIO.toml",
                                   type=click.Path(dir_okay=False, path_type=Path))


def scenario_of(path: Path, system: str | None):
    """The validated scenario at ``path``; one of ``system`` when a system is named.

    Raises
    ------
    ScenarioError
        The file is invalid, or it names another system than ``system``.
    """
    from schuler.study.scenario import load_scenario

    loaded = load_scenario(path)
    if system is not None and loaded.system != system:
        raise ScenarioError(f"{path}: system: {loaded.system!r} is a scenario of schuler {loaded.system}, "
                            f"not of schuler {system}; run it with schuler {loaded.system} or schuler run")
    return loaded


def sweep_command(system: str | None = None) -> click.Command:
    """The ``sweep`` command, for scenarios of any system (``system=None``) or of ``system`` only."""

    @click.command("sweep")
    @SCENARIO_ARGUMENT
    @click.option(
        "--param",
        "params",
        multiple=True,
        metavar="NAME=START:STOP:STEP",
        help="Sweep a run option over a grid (STOP included when on the grid), e.g. "
        "latitude=0:80:10 or drift_east=0.001:0.01:0.001 deg/h; or a list NAME=V1,V2,... "
        "Repeat for a cartesian product.",
    )
    @click.option(
        "--monte-carlo",
        "monte_carlo",
        type=int,
        default=None,
        metavar="N",
        help="Random draws per grid point of the parameters in the scenario's [monte_carlo.normal] "
        "and [monte_carlo.uniform] tables (seed: [monte_carlo] seed).",
    )
    @click.option(
        "--out",
        "out_dir",
        type=FOLDER,
        callback=folder_not_option,
        required=True,
        help="Folder for results.csv, results.parquet, summary.json, plots and the chunk files. "
        "Re-running into the same folder resumes: finished chunks are skipped.",
    )
    @click.option(
        "--scheduler",
        default=None,
        metavar="local|tcp://HOST:PORT",
        help="Evaluate on Dask: 'local' starts a LocalCluster, an address uses a running scheduler.",
    )
    @click.option(
        "--workers",
        type=int,
        default=None,
        metavar="N",
        help="Local worker processes (without --scheduler), sharing the cores' threads among them; or "
        "LocalCluster workers (default 2).",
    )
    @click.option("--chunk-size", type=int, default=None, metavar="N", help="Cases per chunk (default 50000).")
    @click.option("--fidelity", default=None, metavar="NAME",
                  help="The system's evaluation fidelity, e.g. simulated or closed (default: the scenario's, else the "
                       "system's first).")
    @click.option("--csv/--no-csv", "write_csv", default=True, help="Also write results.csv (large for huge sweeps).")
    @click.option("--progress/--no-progress", default=True, help="Show a progress bar on stderr.")
    @click.option("--no-time-limit", is_flag=True, default=False,
                  help="Run even when the sweep is estimated to take longer than the time budget (10 min, or "
                       "SCHULER_TIME_BUDGET).")
    @json_option
    def sweep(scenario, params, monte_carlo, out_dir, scheduler, workers, chunk_size, fidelity, write_csv, progress,
              no_time_limit, as_json):
        """Sweep parameters of a scenario, or run a Monte Carlo, in vectorised chunks.

        One row per case in DIR/results.csv and DIR/results.parquet (a column per
        parameter, in its display unit, and per result), statistics in
        DIR/summary.json and plots DIR/summary_*.png. An interrupted sweep resumes
        where it stopped when run again with the same arguments.
        """
        from schuler.memory import no_time_limit as unlimited
        from schuler.study.sweep import DEFAULT_CHUNK_SIZE, run_sweep

        loaded = scenario_of(scenario, system)
        with unlimited(no_time_limit):
            summary = run_sweep(
                loaded,
                out_dir,
                params,
                monte_carlo,
                chunk_size=DEFAULT_CHUNK_SIZE if chunk_size is None else chunk_size,
                scheduler=scheduler,
                workers=workers,
                progress=progress and not as_json,
                write_csv=write_csv,
                fidelity=fidelity,
            )
        emit(summary, as_json, inputs={"scenario": str(scenario), "params": list(params), "monte_carlo": monte_carlo})

    return sweep


sweep = sweep_command()
"""``schuler sweep``: a scenario of any system."""
