"""What every command shares: options built from Parameters, output, and errors.

Commands stay thin: parse options with the system's
:class:`~schuler.params.ParameterSet`, call one public function, hand its
result to :func:`emit`.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterable
from contextlib import contextmanager
from pathlib import Path

import click

from schuler import __version__
from schuler.exceptions import InvalidParameter, SchulerError, as_options
from schuler.results import json_safe


def parameter_options(parameters):
    """Decorator adding one click option per :class:`Parameter` (values stay strings).

    Strings keep unit text ("0.01 deg/h") intact; :meth:`ParameterSet.parse` converts.
    """

    def decorate(function):
        # former names stay known to click, so that the parameter set can say what they became
        for old in reversed(tuple(getattr(parameters, "renamed", {}))):
            function = click.option("--" + old.replace("_", "-"), old, default=None, hidden=True)(function)
        for spec in reversed(tuple(parameters)):
            if spec.kind == "flag":
                option = click.option(
                    f"{spec.option}/--no-{spec.option[2:]}", spec.name, default=None, help=spec.help_text()
                )
            elif spec.kind == "choice":
                option = click.option(
                    spec.option, spec.name, default=None, metavar="|".join(spec.choices), help=spec.help_text()
                )
            else:
                metavar = "INT" if spec.kind == "integer" else ("VALUE" if not spec.unit else "QTY")
                option = click.option(spec.option, spec.name, default=None, metavar=metavar, help=spec.help_text())
            function = option(function)
        return function

    return decorate


@contextmanager
def options_named(parameters, names: Iterable[str] = ()):
    """Re-raise library errors under the CLI option's name (``speed`` -> ``--speed``).

    Library code names a parameter as the API knows it; at the command line the
    user typed an option. An :class:`InvalidParameter` whose ``name`` is one of
    ``parameters`` (or of ``names``, the command's other options) is raised again with the option; any other
    :class:`SchulerError` whose message starts with ``"name: "`` gets the option in front instead.
    Errors naming nothing in ``parameters`` pass unchanged.

    Examples
    --------
    >>> from schuler.params import Parameter
    >>> speed = Parameter("speed", "m/s", 10.0, "Ground speed.")
    >>> try:
    ...     with options_named([speed]):
    ...         raise InvalidParameter("speed", "must be finite")
    ... except InvalidParameter as error:
    ...     print(error)
    --speed: must be finite
    """
    options = {spec.name: spec.option for spec in parameters} | {name: as_options(f"`{name}`") for name in names}
    try:
        yield
    except InvalidParameter as error:
        if error.name not in options:
            raise
        raise InvalidParameter(options[error.name], error.reason) from None
    except SchulerError as error:
        name, _, rest = str(error).partition(": ")
        if name not in options or not rest:
            raise
        raise type(error)(f"{options[name]}: {rest}") from None


class FolderPath(click.Path):
    """A folder option's value (a :class:`~pathlib.Path`); an empty name is refused, not read as ".".

    click turns ``--out ""`` into the current folder, where the files of a run would then land unasked.
    """

    def __init__(self):
        super().__init__(file_okay=False, path_type=Path)

    def convert(self, value, param, ctx):
        if isinstance(value, str) and not value.strip():
            self.fail("an empty folder name; give a folder (write . for the current one)", param, ctx)
        return super().convert(value, param, ctx)


FOLDER = FolderPath()
"""The type of every ``--out`` folder option."""


def folder_not_option(ctx, param, value: Path | None) -> Path | None:
    """Refuse a folder named like an option (``--out --help`` would create a folder "--help")."""
    if value is not None and str(value).startswith("-"):
        raise click.BadParameter(f"{str(value)!r} looks like an option, not a folder (write ./{value} if meant)")
    return value


json_option = click.option("--json", "as_json", is_flag=True, help="Print a machine-readable JSON result on stdout.")
out_option = click.option(
    "--out",
    "out_dir",
    type=FOLDER,
    default=None,
    callback=folder_not_option,
    help="Folder for figures and data files (created if missing).",
)


def json_document(result, inputs: dict | None = None, parameters=(), files=()) -> dict:
    """What ``--json`` prints: version, SI inputs, the result, and a ``units`` map.

    ``units`` covers the inputs (each parameter's SI unit) and the result's own
    map; keys whose unit is in their name (``_rad``, ``_s``, ``_m_s``) need no entry.
    """
    data = {"schuler_version": __version__, "inputs": json_safe(inputs or {})}
    data.update(result.to_dict())
    units = {p.name: p.si_unit for p in parameters if inputs and p.name in inputs and p.kind in ("quantity", "integer")}
    units.update(data.get("units", {}))
    data["units"] = units
    if files:
        data["files"] = [str(f) for f in files]
    return data


def emit(result, as_json: bool, inputs: dict | None = None, parameters=(), files=()) -> None:
    """Print a result: rich text by default, JSON (see :func:`json_document`) with --json."""
    if as_json:
        click.echo(json.dumps(json_document(result, inputs, parameters, files), indent=2))
        return
    from rich.console import Console

    # a terminal keeps its own width; pipes and logs get 120 columns instead of rich's 80
    console = Console() if sys.stdout.isatty() else Console(width=120)
    console.print(result.render())
    if files:
        folders = sorted({str(Path(f).parent) for f in files})
        console.print(f"wrote {len(files)} file(s) to {', '.join(folders)}")


@contextmanager
def progress_reporter(label: str, enabled: bool = True):
    """A ``progress(done, total)`` callback drawing a bar on stderr (nothing when disabled or not a terminal)."""
    if not enabled or not sys.stderr.isatty():
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

    bar = Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                   console=Console(stderr=True), transient=True)
    task = None

    def progress(done: int, total: int) -> None:
        nonlocal task
        if task is None:
            task = bar.add_task(label, total=total)
        bar.update(task, completed=done)

    with bar:
        yield progress


def warn(message: str) -> None:
    """One line on stderr, for conditions that degrade but do not stop a run."""
    print(f"schuler: warning: {message}", file=sys.stderr)


__all__ = ["FOLDER", "FolderPath", "emit", "json_document", "json_option", "options_named", "out_option",
           "parameter_options", "progress_reporter", "warn"]
