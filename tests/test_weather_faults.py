"""Issue 44's bad input that the scene's own checks cannot see: a seed study whose
points' records pass the free disk is refused before any point runs, exit 2, one line
naming -o, nothing written (the seed study past the memory: tests/test_faults.py's
row and test_seeds.py; gusts and wind files: test_wind_series.py)."""

from __future__ import annotations

import shutil

from rawehelix.cli import main as cli
from rawehelix.studies import needs
from rawehelix.studies.store import outdir

SEED_STUDY = ["study", "turbulent_rated", "--elements", "2", "--vary", "wind.seed=1:6:6",
              "--vary", "wind.speed_m_s=5:9:3", "--quantity", "power_mean_W"]


def test_a_seed_study_past_the_free_disk_is_refused_before_work(tmp_path, capsys, monkeypatch):
    """18 design points + 3 for the sensitivities: the study's files and 21 records
    (studies/store/outdir.py's estimate, independent of the study's code) need 1 kB more
    than the disk is made to have, yet more than the command's own 10 MB."""
    need = outdir.estimate_bytes(needs.get("study"), points=21)
    assert need > outdir.estimate_bytes(needs.get("study")) + 1e3  # the points count
    usage = shutil.disk_usage(tmp_path)
    monkeypatch.setattr(outdir.shutil, "disk_usage",
                        lambda path: usage._replace(free=int(need - 1e3)))
    out = tmp_path / "out"
    code = cli.main([*SEED_STUDY, "-o", str(out)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, err
    assert f"-o: {out}: its filesystem has" in err and "that 'study' writes" in err, err
    assert not out.exists()
