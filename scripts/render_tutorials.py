"""Render the tutorials (docs/tutorials/NAME.py) as pages with their outputs.

    .venv/bin/python scripts/render_tutorials.py [NAME ...] [--small]

Each tutorial is a jupytext percent script: ``# %% [markdown]`` cells are its
prose, ``# %%`` cells its code.  This script executes the code cells one by
one in one namespace (from the repository's root, as a reader would run the
script), captures each cell's printed output and the figures it makes (open
matplotlib figures, and the PNG/GIF files it writes under the tutorial's
output folder), and writes the page docs/tutorials/NAME.md: the prose as
Markdown, the code as ``python`` blocks, the output as ``text`` blocks, the
figures copied to docs/tutorials/NAME_files/.  A header on the page says when,
at which size and with which command its outputs were made.

The pages and their figures are committed; the Sphinx build runs nothing.
tests/test_tutorials.py fails when a page's code differs from its script's
(re-render the page).  ``--small`` renders at the tests' small size
(RAWEHELIX_TUTORIAL_SMALL=1), for a quick look; commit the normal size.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TUTORIALS = ROOT / "docs" / "tutorials"
FIGURES = (".png", ".gif", ".svg", ".jpg")
#: a written GIF larger than this is linked, not shown (the site stays light)
MAX_INLINE_BYTES = 3_000_000


@dataclass(frozen=True)
class Cell:
    kind: str  # "markdown" or "code"
    text: str


def cells(script_text: str) -> list[Cell]:
    """The cells of a percent script, without jupytext's header."""
    lines = script_text.splitlines()
    if lines and lines[0].strip() == "# ---":  # jupytext's YAML header
        end = next(i for i in range(1, len(lines)) if lines[i].strip() == "# ---")
        lines = lines[end + 1:]
    out: list[Cell] = []
    kind, body = None, []

    def close():
        if kind is None:
            return
        if kind == "markdown":
            text = "\n".join(re.sub(r"^# ?", "", ln) if ln.startswith("#") else ln for ln in body)
        else:
            text = "\n".join(body)
        text = text.strip("\n")
        if text.strip():
            out.append(Cell(kind, text))

    for ln in lines:
        m = re.match(r"^# %%(.*)$", ln)
        if m:
            close()
            kind, body = ("markdown" if "[markdown]" in m.group(1) else "code"), []
        elif kind is not None:
            body.append(ln)
    close()
    return out


def code_blocks(page_text: str) -> list[str]:
    """The ``python`` code blocks of a rendered page, in order."""
    return [m.group(1).strip("\n") for m in
            re.finditer(r"^```python\n(.*?)^```$", page_text, re.M | re.S)]


def _fence(text: str) -> str:
    ticks = "````" if "```" in text else "```"
    return f"{ticks}text\n{text.rstrip()}\n{ticks}"


def _figures_under(folder: Path) -> dict[Path, float]:
    if not folder.is_dir():
        return {}
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if p.suffix.lower() in FIGURES}


def render(script: Path, small: bool) -> tuple[str, float]:
    """Execute ``script`` cell by cell; return its page's Markdown and the wall time."""
    name = script.stem
    files = TUTORIALS / f"{name}_files"
    shutil.rmtree(files, ignore_errors=True)
    files.mkdir()
    os.environ.pop("RAWEHELIX_TUTORIAL_OUT", None)
    if small:
        os.environ["RAWEHELIX_TUTORIAL_SMALL"] = "1"
    else:
        os.environ.pop("RAWEHELIX_TUTORIAL_SMALL", None)
    out_dir = ROOT / "results" / "tutorials" / name  # the scripts' default output folder
    shutil.rmtree(out_dir, ignore_errors=True)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    namespace = {"__name__": "__main__", "__file__": str(script)}
    parts: list[str] = []
    figure_count = 0
    start = time.perf_counter()
    for i, cell in enumerate(cells(script.read_text())):
        if cell.kind == "markdown":
            parts.append(cell.text)
            continue
        parts.append(f"```python\n{cell.text}\n```")
        before = _figures_under(out_dir)
        stdout = io.StringIO()
        print(f"[{name}] cell {i} ...", file=sys.stderr, flush=True)
        with contextlib.redirect_stdout(stdout):
            exec(compile(cell.text + "\n", f"{script.name} (cell {i})", "exec"), namespace)
        if stdout.getvalue().strip():
            parts.append(_fence(stdout.getvalue()))
        shown: list[tuple[Path, str]] = []
        for number in plt.get_fignums():
            figure_count += 1
            target = files / f"figure_{figure_count}.png"
            plt.figure(number).savefig(target, dpi=100, bbox_inches="tight")
            shown.append((target, f"figure {figure_count}"))
        plt.close("all")
        after = _figures_under(out_dir)
        for path in sorted(p for p, t in after.items() if before.get(p) != t):
            rel = path.relative_to(out_dir)
            target = files / "_".join(rel.parts)
            shutil.copyfile(path, target)
            shown.append((target, str(rel)))
        for target, label in shown:
            link = f"{name}_files/{target.name}"
            size_bytes = target.stat().st_size
            if size_bytes > MAX_INLINE_BYTES:
                target.unlink()
                parts.append(f"*({label} written, {size_bytes / 1e6:.0f} MB: not shown here)*")
            else:
                parts.append(f"![{label}]({link})")
    wall = time.perf_counter() - start
    if not any(files.iterdir()):
        files.rmdir()
    return _with_header(parts, name, small, wall), wall


def _with_header(parts: list[str], name: str, small: bool, wall: float) -> str:
    size = ("the tests' small size (`RAWEHELIX_TUTORIAL_SMALL=1`)" if small
            else "the tutorial's normal size")
    command = f"`.venv/bin/python scripts/render_tutorials.py {name}" + \
        (" --small`" if small else "`")
    header = (f":::{{note}}\nThe outputs and figures below were made by {command} on "
              f"{time.strftime('%Y-%m-%d', time.gmtime())}, at {size}, in "
              f"{wall:.0f} s of wall time on a shared 2-core machine (rawehelix "
              f"{_version()}).  Run the script itself with "
              f"`.venv/bin/python docs/tutorials/{name}.py` "
              f"({{download}}`{name}.py`); `RAWEHELIX_TUTORIAL_SMALL=1` runs it at the "
              f"tests' small size, `RAWEHELIX_TUTORIAL_OUT=DIR` sets where it writes "
              f"(default `results/tutorials`).\n:::")
    first = parts[0]
    title, _, rest = first.partition("\n")
    assert title.startswith("# "), f"{name}: the first cell must open with the page title"
    head = [title, header] + ([rest.strip("\n")] if rest.strip() else [])
    generated = (f"<!-- generated by scripts/render_tutorials.py from {name}.py: "
                 f"edit the script and re-render, not this page -->")
    return "\n\n".join([generated] + head + parts[1:]) + "\n"


def _version() -> str:
    import rawehelix
    return rawehelix.__version__


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="tutorials to render (default: all)")
    parser.add_argument("--small", action="store_true",
                        help="render at the tests' small size (RAWEHELIX_TUTORIAL_SMALL=1)")
    args = parser.parse_args(argv)
    scripts = sorted(TUTORIALS.glob("*.py"))
    if args.names:
        known = {s.stem: s for s in scripts}
        unknown = [n for n in args.names if n not in known]
        if unknown:
            parser.error(f"unknown tutorial {unknown[0]!r}; allowed: {', '.join(sorted(known))}")
        scripts = [known[n] for n in args.names]
    os.chdir(ROOT)
    for script in scripts:
        page, wall = render(script, args.small)
        script.with_suffix(".md").write_text(page)
        print(f"{script.with_suffix('.md').relative_to(ROOT)}: {wall:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
