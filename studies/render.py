"""Off-screen pyvista pictures of the helix: a tube of radius R whose stripes turn with alpha.

The tube is built ring by ring around the centre line: at node i, with unit
tangent t_i and a normal n_i transported from the previous node, the point at
angle phi is r_i + R (cos phi n_i + sin phi b_i).  The colour is
cos(k (phi - alpha_i)): k = 3 stripes (the helix's three tethers, say) that
wind along s as the twist alpha(s) varies, and spin with alpha_t.
Works without an X server (pyvista.OFF_SCREEN); if pyvista is missing the
functions return None.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

try:  # optional: the rest of rawehelix works without it
    import pyvista
    pyvista.OFF_SCREEN = True
except ImportError:  # pragma: no cover
    pyvista = None

STRIPES = 3
SIDES = 36


def _frames(x: np.ndarray):
    """Tangents and parallel-transported normals along a polyline."""
    t = np.gradient(x, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    n = np.zeros_like(x)
    seed = np.array([0.0, 1.0, 0.0]) if abs(t[0, 1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    n[0] = seed - seed.dot(t[0]) * t[0]
    n[0] /= np.linalg.norm(n[0])
    for i in range(1, len(x)):
        v = n[i - 1] - n[i - 1].dot(t[i]) * t[i]
        n[i] = v / np.linalg.norm(v)
    return t, n, np.cross(t, n)


def tube(x_m: np.ndarray, alpha: np.ndarray, radius_m: float, samples: int = 400):
    """A pyvista StructuredGrid: the tube around x_m (n, 3) with scalar 'stripes'."""
    s = np.linspace(0.0, 1.0, len(x_m))
    si = np.linspace(0.0, 1.0, samples)
    x = np.stack([np.interp(si, s, x_m[:, k]) for k in range(3)], axis=1)
    a = np.interp(si, s, alpha)
    _, n, b = _frames(x)
    phi = np.linspace(0.0, 2 * np.pi, SIDES + 1)
    pts = (x[:, None, :] + radius_m * (np.cos(phi)[None, :, None] * n[:, None, :]
                                       + np.sin(phi)[None, :, None] * b[:, None, :]))
    grid = pyvista.StructuredGrid(pts[..., 0], pts[..., 1], pts[..., 2])
    stripes = np.cos(STRIPES * (phi[None, :] - a[:, None]))
    grid.point_data["stripes"] = stripes.ravel(order="F")
    return grid


def _scene(plotter, x_m, alpha, radius_m, label):
    plotter.add_mesh(tube(x_m, alpha, radius_m), scalars="stripes", cmap="coolwarm",
                     show_scalar_bar=False, smooth_shading=True)
    plotter.add_mesh(pyvista.Line(x_m[0], x_m[-1]), color="grey", line_width=1)
    plotter.add_text(label, font_size=10)
    plotter.camera_position = [(-0.5 * 16, 40.0, -0.4 * 16), (x_m[:, 0].mean(), 0, x_m[:, 2].mean()),
                               (0, 0, -1)]
    plotter.camera.up = (0.0, 0.0, -1.0)  # z points down (Sec. 2.1)
    plotter.reset_camera(bounds=None)
    plotter.camera.zoom(1.3)


def png(path: Path, x_m, alpha, radius_m: float, label: str = "", size=(1600, 700)):
    """One picture of the helix; returns the path, or None without pyvista."""
    if pyvista is None:
        return None
    plotter = pyvista.Plotter(off_screen=True, window_size=size)
    plotter.set_background("white")
    _scene(plotter, np.asarray(x_m), np.asarray(alpha), radius_m, label)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def gif(path: Path, frames, radius_m: float, size=(1000, 450), fps: int = 10):
    """An animation from frames [(label, x_m, alpha), ...]; returns the path or None."""
    if pyvista is None or not frames:
        return None
    import imageio.v2 as imageio
    images = []
    for label, x_m, alpha in frames:
        plotter = pyvista.Plotter(off_screen=True, window_size=size)
        plotter.set_background("white")
        _scene(plotter, np.asarray(x_m), np.asarray(alpha), radius_m, label)
        images.append(plotter.screenshot(return_img=True))
        plotter.close()
    imageio.mimsave(str(path), images, duration=1.0 / fps, loop=0)
    return path
