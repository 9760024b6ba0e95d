"""studies/present/render.py: the geometry (numpy) and, with pyvista, silent off-screen pictures."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

from rawehelix.studies.present import render


def _sagging(n=9, L=16.0, sag=0.05):
    """A helix at 45 degrees, z down, sagging by ``sag`` (m) mid-span."""
    s = np.linspace(0.0, 1.0, n)
    e = np.array([-1.0, 0.0, -1.0]) / np.sqrt(2.0)
    down = np.array([-1.0, 0.0, 1.0]) / np.sqrt(2.0)  # normal to the chord, toward +z_E
    return L * s[:, None] * e + 4 * sag * (s * (1 - s))[:, None] * down


def test_nice_numbers():
    assert [render.nice(v) for v in (0.3, 1.0, 1.4, 3.0, 4.3, 7.5, 18.0, 380.0)] == \
        [1.0, 1.0, 1.0, 2.0, 5.0, 10.0, 20.0, 500.0]


def test_chord_frame_and_magnification():
    x = _sagging(sag=0.05)
    origin, axes = render.chord_frame(x)
    assert np.allclose(axes @ axes.T, np.eye(3))
    X = render.to_chord(x, origin, axes)
    assert np.allclose(X[[0, -1], 1:], 0.0) and X[-1, 0] == pytest.approx(16.0)
    assert X[4, 1] == pytest.approx(-0.05)  # eta points up: the sag is negative
    view = render.View([x], radius_m=0.19)  # deflection from the chord, automatic factors
    assert view.kr == 5.0 and view.k == 20.0  # 0.95 m drawn radius / 0.05 m sag -> 19 -> 20
    assert np.allclose(view.drawn(x)[:, 1], 20.0 * X[:, 1])
    assert np.allclose(view.drawn(x)[:, 0], X[:, 0])
    moved = x + np.array([0.0, 0.01, 0.0])
    ref = render.View([moved], 0.19, reference_m=x, magnification=50.0)
    assert np.allclose(np.linalg.norm(ref.drawn(moved) - ref.chord(x), axis=1), 0.5)
    assert "x50" in ref.caption() and "x5" in ref.caption()


def test_rings_are_normal_to_the_centre_line_and_turn_with_alpha():
    c = np.stack([np.linspace(0, 10, 11), np.zeros(11), np.zeros(11)], axis=1)
    alpha = np.linspace(0.0, np.pi, 11)
    rings, tethers = render.tensegrity(c, alpha, 0.5)
    assert np.allclose(np.linalg.norm(rings - c[:, None, :], axis=2), 0.5)
    assert np.allclose(rings[..., 0], c[:, None, 0])  # in the plane normal to the tangent
    marker = tethers[:, 0] - c  # eta at alpha = 0, turned by alpha about the tangent
    assert np.allclose(marker[:, 1], 0.5 * np.cos(alpha))
    assert np.allclose(np.abs(marker[:, 2]), 0.5 * np.sin(alpha))


@pytest.mark.skipif(not render.available(), reason="pyvista is not installed")
def test_pictures_are_written_and_vtk_is_silent(tmp_path):
    """helix_png, helix_gif (capped frames) and mode_animation in a fresh process
    with no X server: nothing of VTK may reach stderr."""
    script = textwrap.dedent(f"""
        import numpy as np
        from rawehelix.studies.present import render
        from tests_util_render import helix
        x, T = helix()
        a = np.linspace(0.0, 1.0, len(x))
        frames = [(0.1 * k, x + [0.0, 0.001 * k, 0.0], a * k, T) for k in range(40)]
        render.helix_png({str(tmp_path / "h.png")!r}, x, a, T, 0.19, "t", time_s=1.0)
        render.helix_gif({str(tmp_path / "h.gif")!r}, frames, 0.19, "t", reference_m=x)
        u = np.zeros_like(x); u[:, 1] = np.sin(np.linspace(0.0, np.pi, len(x)))
        render.mode_animation({str(tmp_path / "m.gif")!r}, None, x, u, 0 * a, 0.19, "m")
        render.helix_png({str(tmp_path / "plain.png")!r}, x, a, None, 0.19, "plain")
    """)
    helper = tmp_path / "tests_util_render.py"
    x = _sagging()
    helper.write_text("import numpy as np\n"
                      f"def helix():\n    x = np.array({x.tolist()!r})\n"
                      "    return x, np.linspace(203.0, 198.0, len(x))\n")
    env_path = f"{tmp_path}"
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=tmp_path, env={"PYTHONPATH": env_path, "PATH": "/usr/bin:/bin",
                                            "HOME": str(tmp_path)}, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stderr == "" and run.stdout == ""
    from PIL import Image
    for name in ("h.png", "plain.png"):
        assert Image.open(tmp_path / name).size == render.PNG_SIZE
    gif = Image.open(tmp_path / "h.gif")
    assert gif.size == render.GIF_SIZE and gif.n_frames == render.GIF_FRAMES
    assert Image.open(tmp_path / "m.gif").n_frames == render.MODE_FRAMES


@pytest.mark.skipif(not render.available(), reason="pyvista is not installed")
@pytest.mark.parametrize("moving", [True, False], ids=["displacement", "twist"])
def test_the_colour_bar_title_stays_in_the_window(tmp_path, moving):
    """The bar's title is centred over the bar near the right edge: a long one
    ("displacement amplitude", "twist amplitude (rad)") was cut off there.  No
    ink may touch the frame's right edge, and every title line fits."""
    from PIL import Image
    x = _sagging(n=30)
    s = np.linspace(0.0, 1.0, len(x))
    u = np.zeros_like(x)
    if moving:
        u[:, 1] = np.sin(np.pi * s)
    path = render.mode_animation(tmp_path / "m.gif", None, x, u, np.sin(np.pi * s), 0.19,
                                 "Lateral, 9.84 Hz", frames=2)
    frame = Image.open(path)
    frame.seek(0)
    rgb = np.asarray(frame.convert("RGB")).astype(int)
    assert (rgb[:, -3:, :].sum(axis=2) < 600).sum() == 0, "ink at the right edge: clipped"
    for title in ("displacement amplitude", "twist amplitude (rad)", "tension T (N)"):
        assert max(len(line) for line in render.bar_title(title).splitlines()) \
            <= render.BAR_TITLE_CHARS
