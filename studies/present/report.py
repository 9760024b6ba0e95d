"""One self-contained HTML page from data: sections of paragraphs, tables and images.

The page has plain inline CSS and no external resource; images are referenced
by paths relative to the page, and every one of them must exist when the page
is written (a missing figure fails loudly, it does not leave a broken link).

    write_report("results/report.html", [
        Section("Stationary state", ["Newton converged in 3 iterations."],
                tables=[Table(["quantity", "value"], [["T(0) (N)", 202.9]])],
                images=[Figure("stationary/stationary.png", "Sec. 5.1")]),
    ])

:func:`table3_rows` puts computed modes beside the paper's Table 3.
"""

from __future__ import annotations

import html
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from rawehelix.families import FAMILY_LABELS
from rawehelix.studies.present import paper as paper_data
from rawehelix.studies.store import writers


@dataclass
class Table:
    header: list
    rows: list
    caption: str = ""


@dataclass
class Figure:
    path: str | Path
    caption: str = ""


@dataclass
class Section:
    title: str
    paragraphs: list = field(default_factory=list)
    tables: list = field(default_factory=list)   # Table, or dict with header/rows[/caption]
    images: list = field(default_factory=list)   # Figure, path, or (path, caption)


CSS = """
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 1100px; padding: 0 1em; color: #222; line-height: 1.45; }
h1 { font-size: 1.6em; border-bottom: 2px solid #444; padding-bottom: .2em; }
h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #bbb; }
table { border-collapse: collapse; margin: 1em 0; font-size: .92em; }
th, td { border: 1px solid #bbb; padding: .25em .6em; text-align: right; }
th { background: #eee; } td:first-child, th:first-child { text-align: left; }
caption { caption-side: top; text-align: left; font-style: italic; padding-bottom: .3em; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: .9em; color: #555; }
nav a { margin-right: 1em; } .meta { color: #666; font-size: .85em; }
"""


class MissingImage(FileNotFoundError):
    """An image the report refers to does not exist."""


def cell(value) -> str:
    """A table cell: numbers to 4 significant digits, None as N/A."""
    if value is None:
        return "N/A"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return "N/A" if not math.isfinite(value) else f"{value:.4g}"
    return str(value)


def _as_section(s) -> Section:
    return s if isinstance(s, Section) else Section(**s)


def _as_table(t) -> Table:
    return t if isinstance(t, Table) else Table(**t)


def _as_figure(f) -> Figure:
    if isinstance(f, Figure):
        return f
    if isinstance(f, (tuple, list)):
        return Figure(*f)
    return Figure(f)


def _anchor(k: int) -> str:
    return f"s{k + 1}"


def render_html(sections, title: str, base: Path, meta: str = "") -> str:
    """The page as a string; image paths relative to ``base`` (the page's folder).

    Raises MissingImage listing every image that does not exist."""
    sections = [_as_section(s) for s in sections]
    esc = html.escape
    missing, out = [], []
    out.append(f"<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
               f"<title>{esc(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
               f"<h1>{esc(title)}</h1>\n")
    if meta:
        out.append(f"<p class=\"meta\">{esc(meta)}</p>\n")
    out.append("<nav>" + "".join(f"<a href=\"#{_anchor(k)}\">{esc(s.title)}</a>"
                                 for k, s in enumerate(sections)) + "</nav>\n")
    for k, s in enumerate(sections):
        out.append(f"<section id=\"{_anchor(k)}\">\n<h2>{esc(s.title)}</h2>\n")
        out.extend(f"<p>{esc(str(p))}</p>\n" for p in s.paragraphs)
        for t in map(_as_table, s.tables):
            out.append("<table>\n")
            if t.caption:
                out.append(f"<caption>{esc(t.caption)}</caption>\n")
            out.append("<tr>" + "".join(f"<th>{esc(str(h))}</th>" for h in t.header) + "</tr>\n")
            for row in t.rows:
                if len(row) != len(t.header):
                    raise ValueError(f"table {t.caption or t.header}: row {row} has {len(row)} "
                                     f"cells for {len(t.header)} columns")
                out.append("<tr>" + "".join(f"<td>{esc(cell(v))}</td>" for v in row) + "</tr>\n")
            out.append("</table>\n")
        for f in map(_as_figure, s.images):
            path = Path(f.path)
            full = path if path.is_absolute() else base / path
            if not full.is_file():
                missing.append(str(full))
                continue
            src = Path(os.path.relpath(full, base)).as_posix()
            alt = f.caption or path.name
            out.append(f"<figure><img src=\"{esc(src)}\" alt=\"{esc(alt)}\" loading=\"lazy\">"
                       + (f"<figcaption>{esc(f.caption)}</figcaption>" if f.caption else "")
                       + "</figure>\n")
        out.append("</section>\n")
    out.append("</body>\n</html>\n")
    if missing:
        raise MissingImage("report: missing image(s): " + ", ".join(missing))
    return "".join(out)


def write_report(path, sections, title: str = "rawehelix report", meta: str = "") -> Path:
    """Write the page to ``path``; images relative to its folder (or absolute, made
    relative).  Nothing is written if an image is missing (MissingImage)."""
    path = Path(path)
    text = render_html(sections, title, path.parent.resolve() if path.parent.exists()
                       else path.parent.absolute(), meta)
    return writers.write_text(path, text)


# -- Table 3 --------------------------------------------------------------------------------
TABLE3_HEADER = ["Mode", "Dominant (paper)", "lambda, paper", "lambda, computed",
                 "Period (s), paper", "Period (s), computed", "Im lambda: difference"]


def eigenvalue_text(lam: complex) -> str:
    """As in Table 3: '-2.23 ± 271.40i' (normalised)."""
    re, im = round(lam.real, 2) + 0.0, round(abs(lam.imag), 2)
    return f"{re:.2f} ± {im:.2f}i"


def table3_rows(modes_summary, paper=paper_data.TABLE3, rigid=paper_data.TABLE3_RIGID) -> list:
    """Rows (see TABLE3_HEADER): every row of the paper's Table 3 beside the
    computed mode of the same family nearest to it (each computed mode used
    once), then the rigid rotations (largest computed |lambda| among them).

    ``modes_summary``: the ``summary.json`` dict of ``rawehelix modes`` (or its
    ``modes`` list): entries with ``family``, ``eigenvalue`` [re, im]
    (normalised) and ``period_s``."""
    modes = modes_summary["modes"] if isinstance(modes_summary, dict) else modes_summary
    computed = [(complex(*m["eigenvalue"]), m) for m in modes]
    computed = [(complex(lam.real, abs(lam.imag)), m) for lam, m in computed]
    used, rows = set(), []
    for row in paper:
        candidates = [(abs(lam - row.eigenvalue), k) for k, (lam, m) in enumerate(computed)
                      if m["family"] == row.family and k not in used]
        label = FAMILY_LABELS.get(row.family, row.family)
        if not candidates:
            rows.append([label, row.dominant, eigenvalue_text(row.eigenvalue), "not found",
                         row.period_s, None, None])
            continue
        _, k = min(candidates)
        used.add(k)
        lam, m = computed[k]
        diff = f"{100 * (lam.imag - row.eigenvalue.imag) / row.eigenvalue.imag:+.1f} %"
        rows.append([label, row.dominant, eigenvalue_text(row.eigenvalue), eigenvalue_text(lam),
                     row.period_s, m.get("period_s"), diff])
    zeros = [abs(lam) for lam, m in computed if m["family"] == "rigid"]
    rows.append([FAMILY_LABELS["rigid"], rigid.dominant, "≈ 0 ± 0i",
                 f"|lambda| <= {max(zeros):.1e}" if zeros else "not found", None, None, None])
    return rows
