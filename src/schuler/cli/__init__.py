"""The ``schuler`` command: ``schuler SYSTEM ACTION [options]``.

Systems: ``errors`` (INS error propagation), ``vertical`` (gyro vertical),
``calibrate`` (pulse drift calibration), ``align`` (gyrocompassing), ``north``
(ground gyrocompass), ``imu`` (IMU recordings, error models, Allan variance),
``navigate`` (the nonlinear INS); each has ``run`` and ``reproduce``. Studies: ``run
SCENARIO.toml``, ``sweep``, ``report``. Commands are loaded lazily so that
``schuler --help`` is quick.

Errors (a :class:`~schuler.exceptions.SchulerError` or a usage mistake) print one
line on stderr and exit with code 2.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
import warnings

import click

from schuler import __version__
from schuler.exceptions import SchulerError, as_options
from schuler.registry import SUMMARIES, SYSTEM_MODULES, get_system

# The models' matrices are small: BLAS threads cost more than they give on them, and the cores are shared with
# numba's parallel loops and the sweep's workers (mission's covariance analysis: 12 s of CPU with OpenBLAS's
# default threads on a busy 2-core machine, 0.34 s with one). Set before numpy is first imported (click and the
# package's top level do not import it); a value the user set is kept.
for _variable in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("schuler.cli.study:run_scenario", "Run a scenario file (TOML)."),
    "sweep": ("schuler.cli.sweep:sweep", "Sweep parameters or Monte Carlo over a scenario."),
    "report": ("schuler.cli.study:report", "Build the HTML report of all systems."),
    "lab": ("schuler.cli.lab:lab", "Open the interactive lab bench in the browser."),
}
"""The commands beside the systems': where each comes from and its short help (a system's command is generated
from the registry, :data:`schuler.registry.SYSTEM_MODULES`, its help from :data:`schuler.registry.SUMMARIES`)."""


class LazyGroup(click.Group):
    """A group whose subcommands are imported only when used."""

    def list_commands(self, ctx):
        return [*SYSTEM_MODULES, *COMMANDS]

    def get_command(self, ctx, name):
        if name in SYSTEM_MODULES:
            from schuler.cli.systems import system_group

            return system_group(get_system(name))
        if name not in COMMANDS:
            return None
        module_name, attribute = COMMANDS[name][0].split(":")
        return getattr(importlib.import_module(module_name), attribute)

    def format_commands(self, ctx, formatter):
        rows = [(name, SUMMARIES.get(name) or get_system(name).title) for name in SYSTEM_MODULES]
        rows += [(name, help_text) for name, (_, help_text) in COMMANDS.items()]
        with formatter.section("Commands"):
            formatter.write_dl(rows)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="schuler")
def cli():
    """Model, simulate and analyse gyroscopic navigation instruments.

    Bare numbers are in each option's display unit (shown in --help); values
    with units ("0.01 deg/h", "6 h", "1e-4 g") are converted. A bare "g" in an
    acceleration means standard gravity. Add --json for machine-readable output
    and --out DIR to write figures and data.
    """


def _show_warning(message, category, filename, lineno, file=None, line=None):
    print(f"schuler: warning: {as_options(str(message))}", file=sys.stderr)


_SIGNALLED: list[int] = []


def _terminate(signum, frame):
    """SIGTERM ends a run like Ctrl-C: files being written are removed, one line, exit 128 + 15."""
    _SIGNALLED.append(signum)
    raise KeyboardInterrupt


def main(argv=None) -> None:
    """Entry point: run the CLI, turning errors into one line and exit code 2."""
    import matplotlib

    # the command line writes figures, never shows them: no display needed (the library leaves the backend alone)
    matplotlib.use("Agg")
    warnings.showwarning = _show_warning
    handled = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if handled else None
    try:
        code = cli.main(args=argv, prog_name="schuler", standalone_mode=False)
    except click.exceptions.Exit as exit_:
        code = exit_.exit_code
    except (click.exceptions.Abort, KeyboardInterrupt) as stop:
        terminated = bool(_SIGNALLED)
        # a command that keeps what it finished says so in the interrupt's message (a sweep's chunks);
        # click turns a KeyboardInterrupt into an Abort raised from it
        interrupt = stop if isinstance(stop, KeyboardInterrupt) else stop.__cause__
        kept = f"; {interrupt}" if isinstance(interrupt, KeyboardInterrupt) and str(interrupt) else ""
        print(f"schuler: error: {'terminated (SIGTERM)' if terminated else 'interrupted'}; "
              f"partial files were removed{kept}", file=sys.stderr)
        code = 128 + (signal.SIGTERM if terminated else signal.SIGINT)
    except click.ClickException as error:
        print(f"schuler: error: {error.format_message()}", file=sys.stderr)
        code = 2
    except SchulerError as error:
        print(f"schuler: error: {as_options(str(error))}", file=sys.stderr)
        code = 2
    except OSError as error:  # an output folder that cannot be written, a full disk
        where = f": {error.filename}" if error.filename else ""
        print(f"schuler: error: {error.strerror or error}{where}", file=sys.stderr)
        code = 2
    finally:
        if handled:
            signal.signal(signal.SIGTERM, previous)
        _SIGNALLED.clear()
    sys.exit(code if isinstance(code, int) else 0)
