"""File output that never leaves a half-written result, a wrong mode or a replaced link.

Every regular file is written to a temporary file in the destination folder
and moved into place with :func:`os.replace` (atomic on POSIX and Windows), so
an interrupted run leaves either the old file or the new one. The new file gets
the mode a plain ``open()`` would give it (``0o666`` masked by the umask, or the
mode of the file it replaces). A symbolic link is followed: the file it points
to is replaced, the link stays. A FIFO, a character device (``/dev/stdout``) or
``-`` (standard output) is written directly, never replaced. Errors name the
path the user gave, never the temporary file.

A run's set of files (:func:`write_file_set`) is written into a hidden
temporary folder inside the output folder and moved into place at the end,
with SIGINT and SIGTERM held back meanwhile: the folder shows either the whole
new set or none of it. A record in the folder (:data:`FILE_SET_RECORD`) lists
each command's files, so a new run removes the files of the previous run of the
same command that it does not write again (an old figure never sits beside new
data), and leaves every other file alone.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import shutil
import signal
import stat
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

PART_SUFFIX = ".part"
"""Suffix of the temporary files (``.NAME.<random letters>.part``) beside a target."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _streamed(target: Path) -> bool:
    """True for targets that must be written in place: FIFOs, character and block devices."""
    try:
        mode = os.stat(target).st_mode
    except OSError:
        return False
    return stat.S_ISFIFO(mode) or stat.S_ISCHR(mode) or stat.S_ISBLK(mode)


@contextlib.contextmanager
def _naming(tmp: Path | None, shown):
    """Re-raise an OSError about the temporary file as one about the user's path."""
    try:
        yield
    except OSError as error:
        if tmp is None or error.filename in (None, str(tmp), tmp):
            raise OSError(error.errno or errno.EIO, error.strerror or str(error), str(shown)) from None
        raise


@contextlib.contextmanager
def atomic_path(path):
    """Yield a path to write; on success it becomes ``path`` (see the module notes).

    Parameters
    ----------
    path : str or Path
        The file to write.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "a.txt"
    >>> with atomic_path(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text()
    'done'
    """
    shown = path
    if str(path) == "-":
        yield Path("/dev/stdout")
        return
    target = Path(os.path.realpath(path))
    if _streamed(target):
        with _naming(None, shown):
            yield target
        return
    with _naming(None, shown):
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=PART_SUFFIX, dir=target.parent)
        os.close(fd)
    tmp = Path(name)
    try:
        with _naming(tmp, shown):
            yield tmp
            try:
                mode = stat.S_IMODE(os.stat(target).st_mode)
            except FileNotFoundError:
                mode = 0o666 & ~_umask()
            os.chmod(tmp, mode)
            os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()


def remove_stale_parts(folder) -> list[Path]:
    """Delete temporary files and folders (``.*.part``) an interrupted run left in ``folder`` and its subfolders.

    Parameters
    ----------
    folder : str or Path
        Output folder.
    """
    removed = []
    for part in sorted(Path(folder).rglob(f".*{PART_SUFFIX}")):
        if part.is_symlink() or not part.exists():  # a link is never ours; a folder removed above took it along
            continue
        if part.is_dir():
            shutil.rmtree(part, ignore_errors=True)
        else:
            part.unlink()
        removed.append(part)
    return removed


def write_text(path, text: str) -> Path:
    """Write text atomically; returns the path.

    Parameters
    ----------
    path : str or Path
        The file.
    text : str
        Its content.
    """
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_json(path, data) -> Path:
    """Write JSON atomically (``data`` must already be JSON-safe).

    Parameters
    ----------
    path : str or Path
        The file.
    data : dict or list
        JSON-safe data (:func:`schuler.results.json_safe`).
    """
    return write_text(path, json.dumps(data, indent=2) + "\n")


_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_deferred(deliver: bool = True):
    """Hold SIGINT and SIGTERM back until the block ends (a no-op outside the main thread).

    Parameters
    ----------
    deliver : bool
        After a block that ended normally, act on the first signal held back as its handler would have
        (a Ctrl-C raises KeyboardInterrupt); False: drop the signals (the block is already stopping the work).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous: dict[int, object] = {number: signal.getsignal(number) for number in _STOP_SIGNALS}
    for number in _STOP_SIGNALS:
        signal.signal(number, lambda number, frame: held.append(number))
    try:
        yield
    finally:
        for restored, handler in previous.items():
            signal.signal(restored, handler if handler is not None else signal.SIG_DFL)  # type: ignore[arg-type]
    if deliver and held:
        handler = previous[held[0]]
        if callable(handler):
            handler(held[0], None)
        elif handler in (signal.SIG_DFL, None):
            os.kill(os.getpid(), held[0])


FILE_SET_RECORD = ".schuler-files.json"
"""The record, in an output folder, of the files each command wrote there last (names relative to the folder)."""


def write_file_set(out_dir, write: Callable[[Path], list[Path]], command: str) -> list[Path]:
    """Write a run's files so that ``out_dir`` shows the whole new set or none of it (module notes).

    Parameters
    ----------
    out_dir : str or Path
        The output folder (created if missing; removed again if a failed write leaves it empty).
    write : callable
        ``write(folder) -> [paths]``: writes the files into ``folder`` (a temporary folder) and returns them.
    command : str
        What writes the set (``"align run"``): the files its previous run left in ``out_dir`` and this one does
        not write are removed.

    Returns
    -------
    list of Path
        The files written, in ``out_dir``, in the order ``write`` returned them.
    """
    shown = Path(out_dir)
    folder = Path(os.path.realpath(shown))
    created = not folder.exists()
    with _naming(None, shown):
        folder.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=".files.", suffix=PART_SUFFIX, dir=folder))
    try:
        written = [Path(path) for path in write(staging)]
        names = [path.relative_to(staging) if path.is_relative_to(staging) else None for path in written]
        present = {path.relative_to(staging) for path in staging.rglob("*") if path.is_file()}
        ordered = [name for name in names if name is not None] + sorted(present - set(names))
        with signals_deferred():
            for name in dict.fromkeys(ordered):
                _move_into_place(staging / name, shown / name)
            _record(shown, command, [str(name) for name in dict.fromkeys(ordered)])
    except BaseException:
        if created and folder.exists() and not any(path != staging for path in folder.iterdir()):
            shutil.rmtree(folder, ignore_errors=True)
        raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return [shown / name if name is not None else path for name, path in zip(names, written, strict=True)]


def _move_into_place(source: Path, path: Path) -> None:
    """``source`` becomes ``path`` under the rules of :func:`atomic_path` (links followed, mode kept)."""
    target = Path(os.path.realpath(path))
    if not _streamed(target):
        with _naming(source, path):
            target.parent.mkdir(parents=True, exist_ok=True)
            try:
                mode = stat.S_IMODE(os.stat(target).st_mode)
            except FileNotFoundError:
                mode = 0o666 & ~_umask()
            os.chmod(source, mode)
            try:
                os.replace(source, target)
                return
            except OSError as error:
                if error.errno != errno.EXDEV:
                    raise
    # a device, or a link to another file system: copied through an atomic write there
    with atomic_path(path) as tmp:
        shutil.copyfile(source, tmp)


def _record(folder: Path, command: str, names: list[str]) -> None:
    """Remember ``command``'s files in ``folder``; remove those of its previous run that it no longer writes."""
    record = folder / FILE_SET_RECORD
    try:
        sets = json.loads(record.read_text(encoding="utf-8"))
        sets = sets if isinstance(sets, dict) else {}
    except (OSError, ValueError):  # no record yet, or one that is not ours
        sets = {}
    previous = sets.get(command, [])
    for name in previous if isinstance(previous, list) else []:
        old = folder / str(name)
        if name not in names and old.is_file() and not old.is_symlink():  # a link is the user's: left alone
            old.unlink()
    sets[command] = names
    write_json(record, sets)


MIN_FONT_KEY = "schuler-min-font-px"
"""PNG text chunk holding the smallest font size of the figure, in pixels of the image."""


def smallest_font_px(fig, dpi: float) -> float:
    """The smallest font size among the figure's visible texts, in pixels at ``dpi``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : float
        Resolution, dpi (dots per inch).
    """
    from matplotlib.text import Text

    sizes = [t.get_fontsize() for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()]
    return min(sizes) * dpi / 72.0 if sizes else 0.0


def save_figure(fig, path, **kwargs) -> Path:
    """Save a matplotlib figure atomically; the format follows the file suffix.

    A PNG records its smallest font size in pixels (:data:`MIN_FONT_KEY`), so a
    page showing it can check that its text stays legible at the displayed size.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : str or Path
        The file (``.png``, ``.svg`` ...).
    **kwargs
        Passed to ``Figure.savefig``.

    """
    path = Path(path)
    fmt = path.suffix.lstrip(".") or "png"
    if fmt == "png":
        dpi = kwargs.get("dpi", "figure")
        dpi = fig.dpi if dpi == "figure" else dpi
        kwargs.setdefault("metadata", {})[MIN_FONT_KEY] = f"{smallest_font_px(fig, dpi):.2f}"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, **kwargs)
    return path


def save_figure_formats(fig, stem, formats=("png", "svg"), **kwargs) -> list[Path]:
    """Save a figure as ``stem.png``, ``stem.svg`` ... atomically; close it; return the paths.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (closed afterwards).
    stem : str or Path
        Path without suffix.
    formats : tuple of str
        Suffixes to write.
    **kwargs
        Passed to ``Figure.savefig``.
    """
    import matplotlib.pyplot as plt

    stem = Path(stem)
    paths = [save_figure(fig, stem.with_suffix(f".{fmt}"), **kwargs) for fmt in formats]
    plt.close(fig)
    return paths


def write_dataframe_csv(frame, path) -> Path:
    """Write a pandas DataFrame as CSV atomically.

    Parameters
    ----------
    frame : pandas.DataFrame
        The table (units in its column names).
    path : str or Path
        The file.
    """
    with atomic_path(path) as tmp:
        if all(dtype.kind in "iuf" for dtype in frame.dtypes):
            _write_numeric_csv(frame, tmp)
        else:
            frame.to_csv(tmp, index=False)
    return Path(path)


def _write_numeric_csv(frame, path) -> None:
    """Write an all-numeric table as pandas would, through Arrow's CSV writer.

    pandas formats every value in Python (about 8 s for 300,000 rows of 30 columns); Arrow's C++ writer
    does it in about 1 s with the same shortest round-trip digits and empty fields for NaN. The header
    goes through the standard library's writer so that it is quoted only where a name needs it, as pandas
    does.
    """
    import csv

    import pyarrow as pa
    import pyarrow.csv as pa_csv

    with open(path, "w", newline="", encoding="utf-8") as stream:
        csv.writer(stream, lineterminator="\n").writerow([str(name) for name in frame.columns])
    with open(path, "ab") as stream:
        pa_csv.write_csv(pa.Table.from_pandas(frame, preserve_index=False), stream,
                         pa_csv.WriteOptions(include_header=False))
