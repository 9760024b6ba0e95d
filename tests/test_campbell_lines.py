"""The Campbell diagram's lines and crossings (studies/campbell_lines.py) against closed
forms, and its figure from a summary."""

import json

import pytest

from rawehelix.studies import campbell_lines
from rawehelix.studies.present.campbell_figure import campbell_png


def test_orders_hold_each_line_once():
    assert campbell_lines.orders(3) == (1, 2, 3)
    assert campbell_lines.orders(2) == (1, 2)
    assert campbell_lines.orders(1) == (1, 2)
    with pytest.raises(ValueError, match="rotor.blades"):
        campbell_lines.orders(0)


def test_crossings_of_linear_modes_are_exact():
    """A mode f = a + b rpm (Hz) meets the line n rpm / 60 at rpm = a / (n/60 - b): linear
    interpolation is exact for it; the wind interpolates the same way."""
    a, b = 3.0, 0.01
    rpm = [0.0, 40.0, 80.0, 120.0, 160.0]
    wind = [2.0 + 0.05 * r for r in rpm]
    track = [(r, a + b * r, v, 0) for r, v in zip(rpm, wind)]
    found = campbell_lines.crossings({(0, "lateral_in_plane", 0): track[::-1]}, blades=3)
    expected = {f"{n}P": a / (n / 60 - b) for n in (1, 2, 3)}
    expected = {k: r for k, r in expected.items() if 0 <= r <= 160}
    assert {c["line"] for c in found} == set(expected) == {"2P", "3P"}
    for c in found:
        r = expected[c["line"]]
        assert c["rotor_rpm"] == pytest.approx(r, rel=1e-12)
        assert c["frequency_Hz"] == pytest.approx(a + b * r, rel=1e-12)
        assert c["wind_m_s"] == pytest.approx(2.0 + 0.05 * r, rel=1e-12)
        assert (c["family"], c["mode"], c["branch"]) == ("lateral_in_plane", 1, 0)


def test_a_mode_above_every_line_has_no_crossing():
    track = [(r, 50.0 + r, 5.0, 0) for r in (10.0, 20.0, 30.0)]
    assert campbell_lines.crossings({(0, "torsional", 0): track}, blades=3) == []


def test_a_mode_that_appears_starts_its_own_track():
    """rotor_example's torsional family at N = 4: at 54 rpm the slow mode is overdamped
    (2.51, 4.96 Hz oscillate); from 72 rpm it oscillates at 0.30-0.41 Hz below the 2.5 Hz
    mode.  The 2.5 Hz mode keeps its track (its rank changes from 1st to 2nd), the slow
    one starts a new track, and no crossing joins 2.51 Hz to 0.30 Hz."""
    points = [(54.3, 3.0, [2.511, 4.955]), (72.4, 4.0, [0.302, 2.529]),
              (90.4, 5.0, [0.373, 2.531])]
    tracks = campbell_lines.follow(points)
    assert [[(r, f, k) for r, f, _, k in t] for t in tracks] == [
        [(54.3, 2.511, 0), (72.4, 2.529, 1), (90.4, 2.531, 1)], [(54.3, 4.955, 1)],
        [(72.4, 0.302, 0), (90.4, 0.373, 0)]]
    found = campbell_lines.crossings({(0, "torsional", k): t for k, t in enumerate(tracks)}, 3)
    assert all(c["frequency_Hz"] > 2.4 or c["rotor_rpm"] >= 72.4 for c in found), found


def test_slack_band_from_an_envelope_summary():
    """Runs of slack points along each branch (through a fold: f1 goes back), merged
    where they overlap; with a value, the nearest tick's only."""
    def branch(*pairs):
        return [{"f1_Hz": f, "first_limit": k} for f, k in pairs]
    envelope = {"key": "helix.EI_Nm2", "ticks": [
        {"value": 3000.0, "branch": branch((0.8, None), (0.9, "slack"), (1.0, {"kind": "slack"}),
                                           (1.1, "moment_saturation"), (1.4, "slack"),
                                           (1.6, "slack"), (1.5, "slack"))},
        {"value": 6000.0, "branch": branch((0.95, "slack"), (1.2, "slack"), (1.3, None))}]}
    assert campbell_lines.slack_bands_Hz(envelope, 3500.0) == [(0.9, 1.0), (1.4, 1.6)]
    assert campbell_lines.slack_bands_Hz(envelope) == [(0.9, 1.2), (1.4, 1.6)]


def test_figure_from_a_summary(tmp_path):
    summary = {"lines": ["1P", "2P", "3P"], "slack_bands_Hz": [(0.9, 1.0)],
               "points": [{"rotor_rpm": r, "branch": 0, "stable": r < 100}
                          for r in (40.0, 80.0, 120.0)],
               "tracks": [{"branch": 0, "family": "lateral_in_plane",
                           "points": [[r, 3 + 0.01 * r, 5.0, 0, 0.05 if r < 100 else -0.01]
                                      for r in (40.0, 80.0, 120.0)]}],
               "crossings": [{"rotor_rpm": 100.0, "frequency_Hz": 4.0, "line": "3P"}]}
    path = campbell_png(tmp_path / "campbell.png", json.loads(json.dumps(summary)), "t")
    assert path.stat().st_size > 1000
