"""studies/present/report.py and the report half of cli/demo.py, on synthetic data."""

from __future__ import annotations

import html.parser
import os
from pathlib import Path

import pytest

from rawehelix.cli import demo
from rawehelix.studies.present import paper
from rawehelix.studies.present.report import (TABLE3_HEADER, MissingImage, Section, Table, table3_rows,
                                      write_report)

PNG = bytes.fromhex("89504e470d0a1a0a")  # the signature is all the page needs


class _Page(html.parser.HTMLParser):
    """The img sources, external references and text of a page."""

    def __init__(self):
        super().__init__()
        self.images, self.external, self.text = [], [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs["src"])
        for key in ("src", "href"):
            value = attrs.get(key) or ""
            if tag in ("link", "script") or "://" in value or value.startswith("//"):
                self.external.append((tag, value))

    def handle_data(self, data):
        self.text.append(data)


def _parse(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def _assert_images_exist(path: Path, expected: int):
    page = _parse(path)
    assert len(page.images) == expected
    for src in page.images:
        assert not Path(src).is_absolute(), src
        assert (path.parent / src).is_file(), src
    assert page.external == []
    return page


def _picture(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(PNG)
    return path


def test_write_report_references_every_image(tmp_path):
    a = _picture(tmp_path / "out" / "stationary" / "stationary.png")
    b = _picture(tmp_path / "elsewhere" / "helix.gif")  # absolute, outside: made relative
    sections = [
        Section("One", ["First <paragraph> & more."],
                [Table(["quantity", "value"], [["T(0) (N)", 202.91234], ["periodic", True],
                                               ["missing", None]], "numbers")],
                ["stationary/stationary.png", (b, "an animation")]),
        {"title": "Two", "paragraphs": ["plain"], "images": [a]},
    ]
    out = write_report(tmp_path / "out" / "report.html", sections, "synthetic")
    page = _assert_images_exist(out, 3)
    text = "".join(page.text)
    assert "First <paragraph> & more." in text  # escaped, so read back as text
    assert "202.9" in text and "N/A" in text and "yes" in text
    assert "../elsewhere/helix.gif" in page.images


def test_missing_image_fails_loudly(tmp_path):
    _picture(tmp_path / "there.png")
    sections = [Section("S", images=["there.png", "not_there.png"])]
    with pytest.raises(MissingImage, match="not_there.png"):
        write_report(tmp_path / "report.html", sections)
    assert not (tmp_path / "report.html").exists()


def test_table_row_of_wrong_width_fails(tmp_path):
    with pytest.raises(ValueError, match="2 columns"):
        write_report(tmp_path / "r.html", [Section("S", tables=[Table(["a", "b"], [[1, 2, 3]])])])


def _modes_summary(scale=1.0):
    """Table 3 itself, the imaginary parts scaled, plus a rigid rotation."""
    modes = [{"family": r.family, "eigenvalue": [r.eigenvalue.real, scale * r.eigenvalue.imag],
              "period_s": r.period_s, "dominant": []} for r in paper.TABLE3]
    modes.append({"family": "rigid", "eigenvalue": [1e-9, 0.0], "period_s": None,
                  "dominant": []})
    return {"modes": modes[::-1], "elements": 2, "scheme": "spline"}


def test_table3_rows_pair_each_paper_row_with_its_mode():
    rows = table3_rows(_modes_summary(1.01))
    assert len(rows) == len(paper.TABLE3) + 1 and all(len(r) == len(TABLE3_HEADER) for r in rows)
    for row, ref in zip(rows, paper.TABLE3):
        assert row[2].split("±")[1].strip() == f"{abs(ref.eigenvalue.imag):.2f}i"
        assert row[6] == "+1.0 %"
        assert row[4] == ref.period_s
    assert rows[3][3] == "0.00 ± 40.40i" and rows[4][3] == "0.00 ± 20.20i"  # both torsional
    assert rows[-1][3] == "|lambda| <= 1.0e-09"


def test_table3_rows_say_when_a_family_is_missing():
    summary = _modes_summary()
    summary["modes"] = [m for m in summary["modes"] if m["family"] != "longitudinal"]
    rows = table3_rows(summary)
    assert rows[0][3] == "not found" and rows[1][3] != "not found"


def test_table3_rows_on_the_spline_scheme():
    """The paper's scheme at N = 2 lands within 1 % of every Table 3 frequency."""
    from rawehelix.studies import modes, scene
    params = scene.load("stationary_table2", scheme="spline", elements=paper.TABLE3_ELEMENTS)
    rows = table3_rows(modes.compute(params).summary)
    assert all(abs(float(r[6].rstrip(" %"))) < 1.0 for r in rows[:-1]), rows


def _synthetic_demo(tmp_path):
    outdir = tmp_path / "results"
    images = {
        "stationary": [_picture(outdir / "stationary" / "stationary.png")],
        "modes": [_picture(outdir / "modes" / "modes.png"),
                  _picture(outdir / "modes" / "mode_torsional.gif")],
        "modes_spline": [],
        "spin_up": [_picture(outdir / "spin_up" / "dynamics.png"),
                    _picture(outdir / "spin_up" / "helix_10.00s.png"),
                    _picture(outdir / "spin_up" / "helix.gif")],
        "sweep": [_picture(outdir / "sweep" / "sweep.png")],
    }
    summaries = {
        "stationary": {"elements": 16, "degree": 3, "tension_N": {"s0": 202.9, "s1": 198.4},
                       "sag_m": 0.051, "shooting_max_diff_m": 2e-7,
                       "shooting_tension_s0_N": 202.9, "newton_iterations": 4},
        "modes": {**_modes_summary(1.02), "elements": 16, "scheme": "fe"},
        "modes_spline": _modes_summary(1.0),
        "spin_up": {"elements": 8, "target_rpm": 120.0, "simulated_s": 10.0, "wall_s": 8.1,
                    "real_time_factor": 1.23, "steps": 1000, "newton_iterations": 2500,
                    "settling_time_s": None, "tension_range_N": [195.0, 207.0],
                    "final": {"spin_rpm": {"s0": 118.0, "mid": 117.5, "L0": 117.0},
                              "ground_torque_Nm": -24.0, "tension_s0_N": 203.0,
                              "tension_L0_N": 199.0}},
        "sweep": {"elements": 8, "resonance_Hz": 12.5, "peak_tension_N": 564.5,
                  "points": [{"f1_Hz": f, "tension_max_N": t, "tension_min_N": 75.0,
                              "tension_mean_N": 80.0, "periodic": True, "wall_s": 2.0}
                             for f, t in ((9.0, 143.0), (10.0, 244.8), (12.5, 564.5))]},
    }
    return outdir, summaries, images


def test_demo_report_from_summaries(tmp_path):
    outdir, summaries, images = _synthetic_demo(tmp_path)
    wall = {"stationary": 1.5, "modes": 3.0}
    path = demo.build_report(outdir, summaries, images, wall)
    assert path == outdir / "report.html"
    page = _assert_images_exist(path, sum(len(v) for v in images.values()))
    text = "".join(page.text)
    for heading in ("Sec. 5.1", "Table 3", "Sec. 5.2", "Sec. 5.3"):
        assert heading in text
    assert text.count("-2.23 ± 271.40i") == 3  # the paper beside FE and spline, the spline equal
    assert "+2.0 %" in text  # the FE column, 2 % off
    assert "564.5" in text and "first exceeds 200 N at 10 Hz" in text
    assert "117.5" in text and "N/A" in text  # a value, and a missing one (settling time)


def test_demo_report_fails_on_a_missing_picture(tmp_path):
    outdir, summaries, images = _synthetic_demo(tmp_path)
    images["sweep"].append(outdir / "sweep" / "gone.png")
    with pytest.raises(MissingImage, match="gone.png"):
        demo.build_report(outdir, summaries, images)


def test_images_in_lists_pictures(tmp_path):
    _picture(tmp_path / "b.gif")
    _picture(tmp_path / "a.png")
    (tmp_path / "summary.json").write_text("{}")
    assert [p.name for p in demo.images_in(tmp_path)] == ["a.png", "b.gif"]


@pytest.mark.parametrize("where", ["absolute", "relative", "relative, from a subfolder"])
def test_demo_main_runs_the_five_studies(tmp_path, monkeypatch, where):
    """main() against stand-ins for the public API (rh.load_scene, rh.stationary,
    rh.modes, rh.simulate, rh.sweep): the calls, the folders and the page, with the
    output folder absolute or relative to a working directory that is not its parent
    (the default ``results`` once failed: every picture got ``results/`` twice)."""
    import rawehelix as rh
    outdir, summaries, _ = _synthetic_demo(tmp_path)
    calls = []

    class Result:
        def __init__(self, name, picture):
            self.name, self.picture, self.summary = name, picture, summaries[name]

        def write(self, folder):
            calls.append(("write", Path(folder).name))
            _picture(Path(folder) / self.picture)

    def load_scene(name, **overrides):
        calls.append(("load", name, tuple(sorted(overrides.items()))))
        return {"name": name, **overrides}

    def modes(scene):
        spline = scene.get("scheme") == "spline"
        return Result("modes_spline" if spline else "modes", "modes.png")

    def sweep(scene, f1_Hz):
        calls.append(("sweep", tuple(f1_Hz)))
        return Result("sweep", "sweep.png")

    for name, fn in {"load_scene": load_scene, "modes": modes, "sweep": sweep,
                     "stationary": lambda scene: Result("stationary", "stationary.png"),
                     "simulate": lambda scene, until_s: Result("spin_up", "dynamics.png")
                     }.items():
        monkeypatch.setattr(rh, name, fn, raising=False)
    out = tmp_path / "demo"
    if where != "absolute":
        cwd = tmp_path / "elsewhere" if "subfolder" in where else tmp_path
        cwd.mkdir(exist_ok=True)
        monkeypatch.chdir(cwd)
        out = Path(os.path.relpath(out, cwd))
        assert not out.is_absolute()
    path = demo.main(out, log=lambda *a: None)
    assert path == tmp_path / "demo" / "report.html"
    assert ("load", "stationary_table2", (("elements", 2), ("scheme", "spline"))) in calls
    assert ("sweep", demo.SWEEP_F1_HZ) in calls
    assert [c[1] for c in calls if c[0] == "write"] == list(demo.STEPS)
    _assert_images_exist(path, len(demo.STEPS))
