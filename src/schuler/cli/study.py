"""``schuler run``, ``schuler sweep`` and ``schuler report``: studies over the five systems."""

from __future__ import annotations

import json
from pathlib import Path

import click

from schuler import __version__
from schuler.cli.common import emit, folder_not_option, json_option
from schuler.registry import SYSTEM_MODULES

_SCENARIO = click.argument("scenario", metavar="SCENARIO.toml", type=click.Path(dir_okay=False, path_type=Path))


@click.command("run")
@_SCENARIO
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    callback=folder_not_option,
    default=None,
    help="Folder for figures and data files (default: the scenario's [outputs] directory, if any).",
)
@json_option
def run_scenario(scenario: Path, out_dir: Path | None, as_json: bool):
    """Run a scenario file: what `schuler SYSTEM run` does for its parameters.

    The file names the system and sets its run options by name
    (`latitude = "50 deg"`); see examples/*.toml. With a [monte_carlo] table
    and `cases = N`, N members draw its random parameters and the system's own
    random terms. --out and --json override the file's [outputs] table.
    """
    from schuler.cli.systems import execute_run
    from schuler.study.scenario import load_scenario

    loaded = load_scenario(scenario)
    table = loaded.monte_carlo
    members = table.cases if table is not None and table.cases else 0
    execute_run(loaded.definition(), loaded.values, monte_carlo=members, seed=table.seed if table else 0,
                fidelity=loaded.fidelity, out_dir=out_dir or loaded.out_dir, as_json=as_json or loaded.as_json,
                draw=loaded.draw if members else None)


@click.command("sweep")
@_SCENARIO
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
    type=click.Path(file_okay=False, path_type=Path),
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
    help="Local worker processes (without --scheduler), or LocalCluster workers (default 2).",
)
@click.option("--chunk-size", type=int, default=None, metavar="N", help="Cases per chunk (default 50000).")
@click.option("--fidelity", default=None, metavar="NAME",
              help="The system's evaluation fidelity, e.g. simulated or closed (default: the scenario's, else the "
                   "system's first).")
@click.option("--csv/--no-csv", "write_csv", default=True, help="Also write results.csv (large for huge sweeps).")
@click.option("--progress/--no-progress", default=True, help="Show a progress bar on stderr.")
@json_option
def sweep(scenario, params, monte_carlo, out_dir, scheduler, workers, chunk_size, fidelity, write_csv, progress,
          as_json):
    """Sweep parameters of a scenario, or run a Monte Carlo, in vectorised chunks.

    One row per case in DIR/results.csv and DIR/results.parquet (a column per
    parameter, in its display unit, and per result), statistics in
    DIR/summary.json and plots DIR/summary_*.png. An interrupted sweep resumes
    where it stopped when run again with the same arguments.
    """
    from schuler.study.scenario import load_scenario
    from schuler.study.sweep import DEFAULT_CHUNK_SIZE, run_sweep

    loaded = load_scenario(scenario)
    summary = run_sweep(
        loaded,
        out_dir,
        params,
        monte_carlo,
        chunk_size=chunk_size or DEFAULT_CHUNK_SIZE,
        scheduler=scheduler,
        workers=workers,
        progress=progress and not as_json,
        write_csv=write_csv,
        fidelity=fidelity,
    )
    emit(summary, as_json, inputs={"scenario": str(scenario), "params": list(params), "monte_carlo": monte_carlo})


@click.command("report")
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    callback=folder_not_option,
    default=Path("results"),
    show_default=True,
    help="Folder for index.html and its figures.",
)
@click.option(
    "--system",
    "systems",
    multiple=True,
    type=click.Choice(list(SYSTEM_MODULES)),
    help="Only these systems (repeat; default: all).",
)
@click.option(
    "--jobs",
    type=click.IntRange(min=1),
    default=2,
    show_default=True,
    help="Sections built at once, each in its own process.",
)
@json_option
def report(out_dir: Path, systems, jobs: int, as_json: bool):
    """Build the HTML report of every system: DIR/index.html, then print its path.

    Each system reproduces its source's published numbers (modest sizes, so the
    whole report takes about a minute); the page lists the commands to go further.
    """
    from schuler.study.report import build_report

    index = build_report(out_dir, systems or None, jobs=jobs)
    if as_json:
        click.echo(json.dumps({"schuler_version": __version__, "index": str(index)}, indent=2))
    else:
        click.echo(str(index))

