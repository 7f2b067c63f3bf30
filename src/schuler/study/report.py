"""The HTML report: one self-contained page with a section per system.

``build_report(out_dir)`` asks every system for its report section
(:meth:`System.report`, which writes its figures into ``out_dir/figures``) and
writes ``out_dir/index.html``: an introduction, then per system what it is,
its source, the reproduction table (source value, computed value, agreement,
errata explained), its key figures and the commands that reproduce them. The
page needs no script and no network: it is plain HTML with inline CSS and
images beside it.
"""

from __future__ import annotations

import html
import importlib
import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

from schuler import __version__
from schuler.contract import ReportSection, System
from schuler.exceptions import SchulerError
from schuler.io import MIN_FONT_KEY, write_text
from schuler.registry import SYSTEM_MODULES
from schuler.study.systems import load_system

FIGURES = "figures"
"""Subfolder of the report folder that holds the figures."""


@dataclass
class SystemEntry:
    """One system in the report: its section, or why it has none."""

    name: str
    system: System | None
    section: ReportSection | None
    seconds: float = 0.0


def build_report(out_dir, systems=None, jobs: int = 1) -> Path:
    """Build the report into ``out_dir``; returns the path of ``index.html``.

    A system whose module does not exist in this installation is listed as not
    yet available; any error inside an existing system propagates.

    Parameters
    ----------
    out_dir : path
        Report folder (created if missing); figures go into ``out_dir/figures``.
    systems : iterable of str, optional
        System names to include (default: every system of :data:`~schuler.registry.SYSTEM_MODULES`, in the
        order of the toolkit).
    jobs : int
        Sections built at once, number of, each in its own process (1 or less: all in this process).

    Returns
    -------
    Path
        The report page, ``out_dir/index.html``.
    """
    out_dir = Path(out_dir)
    figures = out_dir / FIGURES
    figures.mkdir(parents=True, exist_ok=True)
    began = time.perf_counter()
    names = list(systems or SYSTEM_MODULES)
    loaded = {name: load_system(name) for name in names}
    present = [name for name in names if loaded[name] is not None]
    if jobs > 1 and len(present) > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(min(jobs, len(present)), mp_context=context) as pool:
            futures = {name: pool.submit(build_section, SYSTEM_MODULES[name], figures) for name in present}
            built = {name: future.result() for name, future in futures.items()}
    else:
        built = {name: build_section(SYSTEM_MODULES[name], figures) for name in present}
    entries = [
        SystemEntry(name, loaded[name], *built[name]) if name in built else SystemEntry(name, None, None)
        for name in names
    ]
    return write_text(out_dir / "index.html", render_html(entries, time.perf_counter() - began, figures))


def build_section(module: str, figures: Path) -> tuple[ReportSection, float]:
    """The report section of the system defined in ``module`` and the seconds it took.

    Parameters
    ----------
    module : str
        The module holding the system's ``SYSTEM`` (a value of :data:`~schuler.registry.SYSTEM_MODULES`).
    figures : Path
        Folder the section's figures are written into.

    Returns
    -------
    section : ReportSection
        What the system's ``report`` returned.
    seconds : float
        Wall-clock time it took, s.

    Raises
    ------
    SchulerError
        The system's report failed (the message names the module).
    """
    began = time.perf_counter()
    try:
        section = importlib.import_module(module).SYSTEM.report(figures)
    except SchulerError as error:
        # re-raised as the base class: it crosses process boundaries intact (one argument)
        raise SchulerError(f"report of {module}: {error}") from None
    return section, time.perf_counter() - began


def render_html(entries: list[SystemEntry], seconds: float, figures_dir: Path | None = None) -> str:
    """The report page for the given entries (figure paths relative to ``figures/``).

    ``seconds`` is the time the whole report took, shown in the footer;
    ``figures_dir`` holds the figures (their sizes and fonts set how they are shown).

    Parameters
    ----------
    entries : list of SystemEntry
        The systems, in the order shown (an entry without a section is listed as not yet available).
    seconds : float
        Wall-clock time the whole report took, s.
    figures_dir : Path, optional
        The folder holding the figures (their pixel widths and fonts set how they are shown, their SVG
        copies are linked); None: the page is written without looking at the files.

    Returns
    -------
    str
        The page's HTML (self-contained but for the figure files).
    """
    available = [e for e in entries if e.section is not None]
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        "<title>schuler: report of the gyroscopic navigation instruments</title>",
        f"<style>{_CSS}{_verdict_css()}\n</style>",
        "</head>",
        "<body>",
        "<main>",
        _intro(entries),
        _contents(entries),
    ]
    parts.extend(_section(entry, figures_dir) for entry in entries)
    parts.append(
        f"<footer><p>schuler {html.escape(__version__)}: {len(available)} of {len(entries)} systems, "
        f"built in {seconds:.1f} s. Rebuild with <code>schuler report --out DIR</code>.</p></footer>"
    )
    parts.extend(["</main>", "</body>", "</html>", ""])
    return "\n".join(parts)


def _intro(entries: list[SystemEntry]) -> str:
    return f"""<header>
<h1>schuler: gyroscopic navigation instruments, reproduced</h1>
<p>This report follows an inertial system through its life: calibrate the gyros,
align the platform in azimuth (or let a ground gyrocompass find north), then
navigate with errors bounded by Schuler tuning. Each section takes one classic
source, reproduces its published numbers with the toolkit, and says where and why
a printed number does not follow from the source's own formulas.</p>
<p>Every quantity is computed in SI and shown in the source's units. Each section
ends with the commands that reproduce it; <code>schuler SYSTEM run --help</code>
lists every parameter, and <code>schuler run SCENARIO.toml</code> and
<code>schuler sweep</code> turn a case into a study.</p>
<p>{sum(e.section is not None for e in entries)} of {len(entries)} systems are in this report.</p>
{_legend()}
</header>"""


def _contents(entries: list[SystemEntry]) -> str:
    items = []
    for entry in entries:
        if entry.section is None:
            items.append(f"<li>{html.escape(entry.name)}: not yet available</li>")
        else:
            items.append(
                f'<li><a href="#{_anchor(entry.name)}">{html.escape(entry.section.title)}</a> '
                f"(<code>schuler {html.escape(entry.name)}</code>)</li>"
            )
    return '<nav><h2>Contents</h2><ol>' + "".join(items) + "</ol></nav>"


def _anchor(name: str) -> str:
    return f"system-{name}"


WIDE_PIXELS = 700
"""A figure wider than this (natural size) spans the whole column, so its text stays legible."""


def _figure(figure, figures_dir: Path | None) -> str:
    """One figure: the image at (at most) its natural size, its SVG beside it, the caption."""
    src = html.escape(f"{FIGURES}/{figure.path}", quote=True)
    caption = html.escape(figure.caption)
    attributes, wide, links = "", False, ""
    if figures_dir is not None:
        path = figures_dir / figure.path
        if path.suffix == ".png" and path.exists():
            from PIL import Image

            with Image.open(path) as image:
                width = image.width
                font = image.info.get(MIN_FONT_KEY)
            wide = width > WIDE_PIXELS
            attributes = f' width="{width}"' + (f' data-min-font-px="{html.escape(font)}"' if font else "")
        svg = path.with_suffix(".svg")
        if path.suffix == ".png" and svg.exists():
            links = f' (<a href="{html.escape(f"{FIGURES}/{svg.name}", quote=True)}">SVG</a>)'
    return (f'<figure class="{"wide" if wide else "narrow"}"><a href="{src}"><img src="{src}" '
            f'alt="{html.escape(figure.caption, quote=True)}"{attributes} loading="lazy"></a>'
            f"<figcaption>{caption}{links}</figcaption></figure>")


def _section(entry: SystemEntry, figures_dir: Path | None = None) -> str:
    name = html.escape(entry.name)
    if entry.section is None or entry.system is None:  # not installed: neither exists
        return (
            f'<section id="{_anchor(entry.name)}" class="missing"><h2>{name}</h2>'
            f"<p>Not yet available in this installation (module "
            f"<code>{html.escape(SYSTEM_MODULES[entry.name])}</code> is not installed).</p></section>"
        )
    section, system = entry.section, entry.system
    parts = [
        f'<section id="{_anchor(entry.name)}">',
        f"<h2>{html.escape(section.title)} <small><code>schuler {name}</code></small></h2>",
        f'<p class="source"><strong>Source:</strong> {html.escape(section.source)}</p>',
        _guide_link(system, figures_dir),
        f"<p>{html.escape(section.summary)}</p>",
    ]
    if section.rows:
        parts.append(_reproduction_table(section))
    if section.notes:
        parts.append("<h3>Notes and errata</h3><ul>")
        parts.extend(f"<li>{html.escape(note)}</li>" for note in section.notes)
        parts.append("</ul>")
    if section.figures:
        parts.append('<div class="figures">')
        parts.extend(_figure(figure, figures_dir) for figure in section.figures)
        parts.append("</div>")
    parts.append(_parameters_table(system))
    if section.commands:
        parts.append("<h3>Reproduce</h3>")
        parts.append("<pre><code>" + "\n".join(html.escape(c) for c in section.commands) + "</code></pre>")
    parts.append(f'<p class="timing">Section built in {entry.seconds:.1f} s.</p>')
    parts.append("</section>")
    return "\n".join(parts)


GUIDE = Path(__file__).resolve().parents[3] / "docs" / "_build" / "html" / "guide"
"""Where ``make docs`` puts the user guide's pages, in a checkout (one page per system: ``System.guide``)."""


def _guide_link(system: System | None, figures_dir: Path | None) -> str:
    """The system's guide chapter: a relative link when the built guide is beside the report, else its name."""
    if system is None or not system.guide:
        return ""
    page = GUIDE / f"{system.guide}.html"
    if figures_dir is not None and page.exists():
        href = os.path.relpath(page, Path(figures_dir).resolve().parent)
        return (f'<p class="guide"><strong>Guide:</strong> <a href="{html.escape(href, quote=True)}">'
                f"{html.escape(system.guide)}</a></p>")
    return (f'<p class="guide"><strong>Guide:</strong> the chapter <code>guide/{html.escape(system.guide)}.html</code> '
            "of the documentation (<code>make docs</code> builds it into <code>docs/_build/html</code>)</p>")


def _number(value) -> str:
    if value is None:
        return "&mdash;"
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, (int, float)):
        if isinstance(value, float) and not math.isfinite(value):
            return html.escape(str(value))
        if 1e4 <= abs(value) < 1e9:
            return html.escape(f"{value:,.6g}" if abs(value) < 1e6 else f"{value:,.0f}")  # 1,620,000 not 1.62e+06
        return html.escape(f"{value:.6g}")
    return html.escape(str(value))


VERDICTS = {
    "agrees": ("#116329", "#dafbe1", "the computed value is within the stated tolerance of the printed one"),
    "tuned": ("#0550ae", "#ddf4ff", "it agrees, but an input was chosen so that it does (the note says which)"),
    "erratum": ("#6639ba", "#fbefff", "it does not agree, and the note explains the source's mistake"),
    "not-printed": ("#57606a", "#f3f4f6", "a computed value the source does not give"),
    "differs": ("#a40e26", "#ffebe9", "it does not agree and nothing explains it"),
}
"""Each kind of verdict (:mod:`schuler.reproduction`): its text colour, its background and what it means."""


def verdict_kind(verdict: str) -> str:
    """The kind of a reproduction verdict: a key of :data:`VERDICTS` (its colour in the report).

    Parameters
    ----------
    verdict : str
        A row's verdict, as :func:`schuler.reproduction.compare` writes it (``"agrees within 0.5 %"``).

    Returns
    -------
    str
        ``"agrees"``, ``"tuned"``, ``"erratum"``, ``"not-printed"`` or ``"differs"`` (anything else).

    Examples
    --------
    >>> verdict_kind("tuned to match within 1 %"), verdict_kind("not printed in the source")
    ('tuned', 'not-printed')
    """
    for prefix, kind in (("agrees", "agrees"), ("tuned", "tuned"), ("erratum", "erratum"),
                         ("not printed", "not-printed")):
        if verdict.startswith(prefix):
            return kind
    return "differs"


def _legend() -> str:
    items = "".join(f'<li><span class="verdict {kind}">{kind.replace("-", " ")}</span>: {html.escape(meaning)}</li>'
                    for kind, (_, _, meaning) in VERDICTS.items())
    return f'<div class="legend"><strong>Verdicts</strong> of the reproduction tables:<ul>{items}</ul></div>'


def _verdict_css() -> str:
    return "\n".join(f".verdict.{kind} {{ color: {colour}; background: {background}; }}"
                     for kind, (colour, background, _) in VERDICTS.items())


def _reproduction_table(section: ReportSection) -> str:
    rows = []
    for row in section.rows:
        rows.append(
            f"<tr><td>{html.escape(row.quantity)}</td><td>{html.escape(row.printed or '-')}</td>"
            f"<td>{html.escape(row.where)}</td><td>{_number(row.computed)}</td><td>{html.escape(row.unit)}</td>"
            f'<td class="verdict {verdict_kind(row.verdict)}">{html.escape(row.verdict)}</td>'
            f"<td>{html.escape(row.note)}</td></tr>"
        )
    counts = {kind: sum(verdict_kind(row.verdict) == kind for row in section.rows) for kind in VERDICTS}
    summary = ", ".join(f'<span class="verdict {kind}">{n} {kind.replace("-", " ")}</span>'
                        for kind, n in counts.items() if n)
    return (
        f"<h3>Reproduction ({summary})</h3>"
        "<table class=\"reproduction\"><thead><tr><th>quantity</th><th>printed</th><th>where</th><th>computed</th>"
        "<th>unit</th><th>verdict</th><th>note</th></tr></thead><tbody>" + "".join(rows) + "</tbody></table>"
    )


def _parameters_table(system: System) -> str:
    rows = []
    for spec in system.parameters:
        unit = spec.unit if spec.kind == "quantity" else spec.kind
        allowed = spec.range_text() if spec.kind in ("quantity", "integer") else ", ".join(spec.choices)
        default = "not set" if spec.default is None else str(spec.default)
        rows.append(
            f"<tr><td><code>{html.escape(spec.option)}</code></td><td>{html.escape(unit)}</td>"
            f"<td>{html.escape(default)}</td><td>{html.escape(allowed)}</td><td>{html.escape(spec.help)}</td></tr>"
        )
    return (
        f"<details><summary>Parameters of <code>schuler {html.escape(system.name)} run</code> "
        f"(also the keys of a scenario file)</summary>"
        "<table><thead><tr><th>option</th><th>unit</th><th>default</th><th>allowed</th><th>meaning</th></tr></thead>"
        "<tbody>" + "".join(rows) + "</tbody></table></details>"
    )


_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0; color: #1d2430;
       background: #fafbfc; line-height: 1.5; }
main { max-width: 1100px; margin: 0 auto; padding: 1.5rem 2rem 3rem; }
h1 { font-size: 1.8rem; margin-bottom: 0.3rem; }
h2 { border-bottom: 2px solid #d0d7de; padding-bottom: 0.2rem; margin-top: 2.5rem; }
h2 small { font-weight: normal; font-size: 0.6em; color: #57606a; }
section.missing h2 { color: #8c959f; }
table { border-collapse: collapse; width: 100%; margin: 0.8rem 0; font-size: 0.9rem; }
th, td { border: 1px solid #d0d7de; padding: 0.3rem 0.5rem; text-align: left; vertical-align: top; }
thead th { background: #eef1f4; }
.verdict { font-weight: 600; padding: 0 0.25rem; border-radius: 3px; }
.legend ul { margin: 0.2rem 0; padding-left: 1.2rem; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(500px, 1fr)); gap: 1rem; }
figure { margin: 0; background: #fff; border: 1px solid #d0d7de; padding: 0.5rem; }
figure.wide { grid-column: 1 / -1; }
figure img { max-width: 100%; height: auto; display: block; margin: 0 auto; }
figcaption { font-size: 0.85rem; color: #57606a; }
pre { background: #f3f4f6; padding: 0.8rem; overflow-x: auto; }
code { font-family: ui-monospace, "SFMono-Regular", Menlo, monospace; font-size: 0.9em; }
details { margin: 0.8rem 0; }
.timing, footer { color: #57606a; font-size: 0.85rem; }
"""
