"""``schuler run`` and ``schuler report``: studies over the systems (``schuler sweep``: :mod:`schuler.cli.sweep`)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from schuler import __version__
from schuler.cli.common import FOLDER, folder_not_option, json_option
from schuler.cli.sweep import SCENARIO_ARGUMENT
from schuler.registry import SYSTEM_MODULES


@click.command("run")
@SCENARIO_ARGUMENT
@click.option(
    "--out",
    "out_dir",
    type=FOLDER,
    callback=folder_not_option,
    default=None,
    help="Folder for figures and data files (default: the scenario's [outputs] directory, if any).",
)
@click.option("--no-time-limit", is_flag=True, default=False,
              help="Run even when the work is estimated to take longer than the time budget (10 min, or "
                   "SCHULER_TIME_BUDGET).")
@click.option("--workers", type=click.IntRange(min=1), default=1, metavar="N", show_default=True,
              help="Processes evaluating the Monte Carlo's members, sharing the cores (1: this process); the "
                   "statistics do not depend on it.")
@json_option
def run_scenario(scenario: Path, out_dir: Path | None, no_time_limit: bool, workers: int, as_json: bool):
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
                draw=loaded.draw if members else None, time_limit=not no_time_limit, workers=workers)


@click.command("report")
@click.option(
    "--out",
    "out_dir",
    type=FOLDER,
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

