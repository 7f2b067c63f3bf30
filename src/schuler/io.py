"""File output that never leaves a half-written result, a wrong mode or a replaced link.

Every regular file is written to a temporary file in the destination folder
and moved into place with :func:`os.replace` (atomic on POSIX and Windows), so
an interrupted run leaves either the old file or the new one. The new file gets
the mode a plain ``open()`` would give it (``0o666`` masked by the umask, or the
mode of the file it replaces). A symbolic link is followed: the file it points
to is replaced, the link stays. A FIFO, a character device (``/dev/stdout``) or
``-`` (standard output) is written directly, never replaced. Errors name the
path the user gave, never the temporary file.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import stat
import tempfile
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
    """Delete temporary files (``.*.part``) an interrupted run left in ``folder`` and its subfolders.

    Parameters
    ----------
    folder : str or Path
        Output folder.
    """
    removed = []
    for part in Path(folder).rglob(f".*{PART_SUFFIX}"):
        if part.is_file():
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
        frame.to_csv(tmp, index=False)
    return Path(path)
