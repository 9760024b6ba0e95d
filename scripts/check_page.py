#!/usr/bin/env python3
"""Check that every local file an HTML page refers to exists: ``check_page.py PAGE [PAGE ...]``.

Reads each page's ``src`` and ``href`` attributes; a reference with a scheme
(``https:``, ``mailto:``) or a bare ``#anchor`` is not a local file.  Prints one
line a missing file and exits 1 if any is missing, 0 otherwise.  CI runs it on
the demo's report.html; the docs tests on the built site.
"""

from __future__ import annotations

import html.parser
import sys
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _References(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.refs = []

    def handle_starttag(self, tag, attrs):
        self.refs.extend(v for k, v in attrs if k in ("src", "href") and v)


def local_references(page: Path) -> list[Path]:
    """The files ``page`` refers to on disk, resolved against its folder."""
    parser = _References()
    parser.feed(Path(page).read_text(encoding="utf-8"))
    out = []
    for ref in parser.refs:
        parts = urlsplit(ref)
        if parts.scheme or parts.netloc or not parts.path:
            continue
        out.append((Path(page).parent / unquote(parts.path)).resolve())
    return out


def missing_references(page: Path) -> list[Path]:
    return [p for p in local_references(page) if not p.exists()]


def main(argv=None) -> int:
    pages = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not pages:
        print("usage: check_page.py PAGE [PAGE ...]", file=sys.stderr)
        return 2
    bad = 0
    for page in pages:
        if not page.is_file():
            print(f"check_page: {page}: no such page")
            bad += 1
            continue
        refs = local_references(page)
        missing = [p for p in refs if not p.exists()]
        for p in missing:
            print(f"check_page: {page} refers to a missing file: {p}")
        bad += len(missing)
        if not missing:
            print(f"check_page: {page}: all {len(refs)} local references exist")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
