"""Off-screen pyvista pictures of the helix as the tensegrity it is.

At every drawn node i the helix is a ring of radius R normal to the local
tangent t_i, turned about t_i by the twist alpha_i (Eq. 26: alpha is the
rotation of the cross-section); a red spoke marks the ring's reference point so
the rotation shows.  Lines join corresponding points of consecutive rings: the
tethers, which wind when alpha varies along s.  The centre line is coloured by
the tension (colour bar in N).

The picture is drawn in the chord frame of the reference centre line: xi along
the chord from the ground end (the ruler, in m), eta normal to it in the
x_E-z_E plane (up), zeta = xi x eta (= -y_E for the scenes of Sec. 5).  The
helix is 16 m long and 0.19 m in radius (Table 2) and its deflections are
centimetres, so two stated factors make it readable: the displacement from
the reference (the stationary state, or the chord) and the ring radius are
drawn magnified.

Everything works without an X server and prints nothing of VTK (its logger and
warnings are switched off at import).  Without pyvista, :func:`available` is
False and every function returns None.
"""

from __future__ import annotations

import functools
import logging
import math
import os
import pickle
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np

#: VTK's wheels and DOLFINx's libraries clash when DOLFINx is loaded first: the
#: first colour bar drawn then dies in std::regex (std::bad_alloc inside
#: vtkScalarBarActor::LayoutTicks, a C++ library ABI clash), killing the
#: process.  So once DOLFINx is loaded before VTK, every picture is drawn in a
#: fresh interpreter that loads this file alone (it imports nothing of
#: rawehelix): :func:`_in_clean_process`.
_VTK_AFTER_DOLFINX = "dolfinx" in sys.modules

try:  # optional: the rest of rawehelix works without it
    import pyvista
    from vtkmodules.vtkCommonCore import vtkLogger, vtkObject
except ImportError:  # pragma: no cover
    pyvista = None
else:
    pyvista.OFF_SCREEN = True
    # VTK's logger prints "bad X server connection" before falling back to EGL
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    vtkObject.GlobalWarningDisplayOff()

TETHERS = 6          # tethers drawn between consecutive rings
RING_SIDES = 48      # polygon sides of a drawn ring
MAX_RINGS = 33       # more nodes than this are subsampled
MIN_RINGS = 17       # fewer nodes than this (spline N = 2) are interpolated
PNG_SIZE = (1600, 600)
GIF_SIZE = (800, 320)
GIF_FRAMES = 30      # at most, per animation
MODE_FRAMES = 16     # per cycle
CMAP = "viridis"
VIEW_DEG = (30.0, 16.0)  # camera turned toward the ground end, and above the helix's plane


def available() -> bool:
    """True when pyvista (and so VTK) can be imported."""
    return pyvista is not None


# -- geometry (numpy only) ------------------------------------------------------------
def nice(value: float) -> float:
    """The 1-2-5 number nearest to ``value`` (in log scale); 1 for value <= 1."""
    if not np.isfinite(value) or value <= 1.0:
        return 1.0
    exp = math.floor(math.log10(value))
    best = min((m * 10.0 ** e for e in (exp, exp + 1) for m in (1, 2, 5)),
               key=lambda c: abs(math.log(c / value)))
    return float(best)


def chord_frame(x_m: np.ndarray):
    """Origin and rows (xi, eta, zeta) of the chord frame of a centre line (n, 3).

    xi: along the chord from the ground end; eta: normal to it in the x_E-z_E
    plane, pointing up (z_E points down, Sec. 2.1); zeta = xi x eta."""
    x_m = np.asarray(x_m, dtype=float)
    xi = x_m[-1] - x_m[0]
    xi = xi / np.linalg.norm(xi)
    up = np.array([0.0, 0.0, -1.0])  # -k_E
    eta = up - up.dot(xi) * xi
    if np.linalg.norm(eta) < 1e-9:  # vertical chord: any horizontal normal
        eta = np.array([1.0, 0.0, 0.0])
    eta /= np.linalg.norm(eta)
    return x_m[0].copy(), np.stack([xi, eta, np.cross(xi, eta)])


def to_chord(x_m, origin, axes):
    return (np.asarray(x_m, dtype=float) - origin) @ axes.T


def chord_reference(x_m: np.ndarray) -> np.ndarray:
    """The straight chord sampled at the projections of x_m: reference of a lone picture."""
    origin, axes = chord_frame(x_m)
    xi = (np.asarray(x_m) - origin) @ axes[0]
    return origin + xi[:, None] * axes[0][None, :]


def auto_radius_magnification(length_m: float, radius_m: float) -> float:
    """Drawn ring radius about 1/18 of the length: x5 for Table 2."""
    return nice(length_m / (18.0 * radius_m))


def auto_magnification(max_displacement_m: float, drawn_radius_m: float) -> float:
    """The largest drawn displacement about one drawn ring radius (1 if nothing moves)."""
    if max_displacement_m < 1e-12 * max(drawn_radius_m, 1.0):
        return 1.0
    return nice(drawn_radius_m / max_displacement_m)


def _ring_nodes(n: int) -> np.ndarray:
    """Fractional node indices of the drawn rings."""
    if n > MAX_RINGS:
        return np.linspace(0, n - 1, MAX_RINGS)
    if n < MIN_RINGS:
        return np.linspace(0, n - 1, MIN_RINGS)
    return np.arange(n, dtype=float)


def _at(values: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Linear interpolation of nodal values (n, ...) at fractional indices k."""
    idx = np.arange(len(values))
    if values.ndim == 1:
        return np.interp(k, idx, values)
    return np.stack([np.interp(k, idx, values[:, j]) for j in range(values.shape[1])], axis=1)


def tensegrity(c: np.ndarray, alpha: np.ndarray, radius: float):
    """Ring polygons, tether end points and marker points around centres c (m, 3).

    The ring at c_i is normal to the tangent t_i; its reference direction is
    the frame's eta projected normal to t_i (the same for every time and mode),
    turned by alpha_i about t_i.  Returns rings (m, RING_SIDES, 3), tether
    points (m, TETHERS, 3) (point 0 is the marker)."""
    t = np.gradient(c, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    eta = np.array([0.0, 1.0, 0.0])  # chord-frame coordinates
    n = eta[None, :] - (t @ eta)[:, None] * t
    n /= np.linalg.norm(n, axis=1)[:, None]
    b = np.cross(t, n)

    def circle(phi):  # phi (k,) -> (m, k, 3)
        ang = alpha[:, None] + phi[None, :]
        return c[:, None, :] + radius * (np.cos(ang)[..., None] * n[:, None, :]
                                         + np.sin(ang)[..., None] * b[:, None, :])
    rings = circle(np.linspace(0.0, 2 * np.pi, RING_SIDES, endpoint=False))
    tethers = circle(np.linspace(0.0, 2 * np.pi, TETHERS, endpoint=False))
    return rings, tethers


# -- drawing --------------------------------------------------------------------------
class View:
    """Chord frame, reference and the two stated magnifications of a picture.

    A state x_m (n, 3) is drawn in chord coordinates as
    ``ref + magnification (x - ref)``, ref being ``reference_m`` (same nodes)
    or, when None, the projection of each node on the chord; the ring radius
    is drawn as ``radius_magnification radius_m``.  Factors left None are
    chosen from ``states``: the ring radius about 1/18 of the length, the
    largest displacement about one drawn ring radius."""

    def __init__(self, states, radius_m: float, reference_m=None, magnification=None,
                 radius_magnification=None, reference_label="the reference"):
        base = np.asarray(states[0] if reference_m is None else reference_m, dtype=float)
        self.origin, self.axes = chord_frame(base)
        self.length = float(np.linalg.norm(base[-1] - base[0]))
        self.reference = None if reference_m is None else self.chord(reference_m)
        self.label = ("deflection from the chord" if reference_m is None
                      else f"displacement from {reference_label}")
        self.radius_m = float(radius_m)
        self.kr = float(radius_magnification or auto_radius_magnification(self.length, radius_m))
        if magnification is None:
            dmax = max(float(np.linalg.norm(self._offset(self.chord(x)), axis=1).max())
                       for x in states)
            magnification = auto_magnification(dmax, self.kr * self.radius_m)
        self.k = float(magnification)

    def chord(self, x_m):
        return to_chord(x_m, self.origin, self.axes)

    def _offset(self, X):
        if self.reference is None:
            return X * np.array([0.0, 1.0, 1.0])
        return X - self.reference

    def drawn(self, x_m):
        X = self.chord(x_m)
        return X + (self.k - 1.0) * self._offset(X)

    def caption(self, what=None, relative_twist=False) -> str:
        what = what or f"{self.label} drawn x{self.k:g}"
        side = "-y_E" if self.axes[2][1] < 0 else "+y_E"
        turn = "alpha - alpha(0)" if relative_twist else "the twist alpha"
        return (f"{what};  ring radius {self.radius_m:.2f} m drawn x{self.kr:g}\n"
                f"rings turned by {turn} (red spoke), {TETHERS} tethers (blue); "
                f"chord horizontal, seen from {side}")


#: the most characters a line of the colour bar's title has: VTK centres the title
#: over the bar, near the window's right edge, and clips what passes it (an 800 px
#: GIF holds 13 characters there: "tension T (N)")
BAR_TITLE_CHARS = 13


def bar_title(title: str | None) -> str | None:
    """The colour bar's title in lines short enough to stay in the window."""
    if title is None:
        return None
    return textwrap.fill(title, BAR_TITLE_CHARS, break_long_words=False)


class _Drawing:
    """One off-screen plotter with the helix actors; :meth:`show` moves them in place."""

    def __init__(self, view: View, clim, size, scalar_title="tension T (N)"):
        self.view = view
        self.clim = list(clim)
        self.size = tuple(size)
        self.scalar_title = scalar_title
        self.big = max(size) > 1000
        self.font = 1.0 if self.big else 0.75
        self.meshes = None
        self.p = pyvista.Plotter(off_screen=True, window_size=list(size))
        self.p.set_background("white")
        self.p.enable_anti_aliasing("ssaa")

    def _geometry(self, x_m, alpha):
        c = self.view.drawn(x_m)
        k = _ring_nodes(len(c))
        centres = _at(c, k)
        rings, tethers = tensegrity(centres, _at(np.asarray(alpha, dtype=float), k),
                                    self.view.kr * self.view.radius_m)
        return {"centre": c, "rings": rings.reshape(-1, 3), "tethers": tethers.reshape(-1, 3),
                "spokes": np.vstack([centres, tethers[:, 0]]), "markers": tethers[:, 0].copy()}

    @staticmethod
    def _lines(points, cells):
        return pyvista.PolyData(points, lines=np.asarray(cells, dtype=np.int64))

    def _build(self, g, scalars):
        n_c, m = len(g["centre"]), len(g["markers"])
        s, tt = RING_SIDES, TETHERS
        rings = np.hstack([np.full((m, 1), s + 1), np.arange(m)[:, None] * s
                           + np.r_[np.arange(s), 0][None, :]]).ravel()
        teth = np.array([[2, i * tt + j, (i + 1) * tt + j]
                         for i in range(m - 1) for j in range(tt)]).ravel()
        spokes = np.array([[2, i, m + i] for i in range(m)]).ravel()
        self.meshes = {"rings": self._lines(g["rings"], rings),
                       "tethers": self._lines(g["tethers"], teth),
                       "spokes": self._lines(g["spokes"], spokes),
                       "markers": pyvista.PolyData(g["markers"]),
                       "centre": self._lines(g["centre"], np.r_[n_c, np.arange(n_c)])}
        self.meshes["centre"]["scalar"] = scalars
        lw = 2  # pixels before SSAA's downsampling
        p = self.p
        p.add_mesh(self.meshes["tethers"], color="#4f6d8f", line_width=lw)
        p.add_mesh(self.meshes["rings"], color="#2b2b2b", line_width=lw)
        p.add_mesh(self.meshes["spokes"], color="#d62728", line_width=lw + 1)
        p.add_mesh(self.meshes["markers"], color="#d62728", point_size=5 * lw + 2,
                   render_points_as_spheres=True)
        bar = dict(title=bar_title(self.scalar_title), vertical=True, position_x=0.9 if self.big else 0.88,
                   position_y=0.2,
                   height=0.6, width=0.03, n_labels=5, fmt="%.4g", color="black",
                   title_font_size=int(20 * self.font), label_font_size=int(18 * self.font),
                   unconstrained_font_size=True)
        if self.scalar_title is None:  # nothing to colour by (no tension given)
            p.add_mesh(self.meshes["centre"], color="#1f77b4", line_width=5 * lw,
                       render_lines_as_tubes=True)
        else:
            p.add_mesh(self.meshes["centre"], scalars="scalar", cmap=CMAP, clim=self.clim,
                       line_width=5 * lw, render_lines_as_tubes=True, scalar_bar_args=bar)
        self._camera()

    def _camera(self):
        p, L = self.p, self.view.length
        r = 1.6 * self.view.kr * self.view.radius_m
        bounds = [0.0, L, -r, r, -r, r]
        a, b = (math.radians(v) for v in VIEW_DEG)
        d = np.array([-math.sin(a) * math.cos(b), math.sin(b), math.cos(a) * math.cos(b)])
        wide = 1.24 if self.big else 1.36  # visible width / L: the helix left of the colour bar
        focal = np.array([(0.5 + 0.25 * (wide - 1.0)) * L, 0.0, 0.0])
        p.camera.focal_point = focal
        p.camera.position = focal + 4.0 * L * d
        up = np.cross(d, [1.0, 0.0, 0.0])  # the chord horizontal on the screen
        p.camera.up = up if up[1] > 0 else -up
        p.enable_parallel_projection()
        step = nice(L / 8.0)
        ticks = int(L // step)
        right = np.cross(d, up if up[1] > 0 else -up)  # the screen's horizontal
        z = 1.25 * r * right[1] / right[2]  # below the centre line's ends on the screen
        p.add_ruler([0.0, -1.25 * r, z], [ticks * step, -1.25 * r, z], title=" ",
                    number_labels=ticks + 1, label_format="%.0f m", font_size_factor=0.5,
                    label_size_factor=0.9 if self.big else 1.6, tick_length=8, label_color="black",
                    tick_color="black")
        p.reset_camera(bounds=bounds)
        p.camera.parallel_scale = 0.5 * wide * L * self.size[1] / self.size[0]

    def show(self, x_m, alpha, scalars, title: str, caption: str):
        """Draw one state; returns the RGB image (h, w, 3).  One render per call."""
        g = self._geometry(x_m, alpha)
        if self.meshes is None:
            self._build(g, scalars)
            w, h = self.size
            self.texts = [self._text(title, (w // 2, h - 8), 16, "center", "top", "black"),
                          self._text(caption, (8, 6), 11, "left", "bottom", "#333333")]
        else:
            for key in ("rings", "tethers", "spokes", "markers", "centre"):
                self.meshes[key].points = g[key]
            self.meshes["centre"]["scalar"] = np.asarray(scalars, dtype=float)
            self.texts[0].SetInput(title)
            self.texts[1].SetInput(caption)
            self.p.render()
        return self.p.screenshot(return_img=True)

    def _text(self, text, xy, points, horizontal, vertical, color):
        """A text of fixed size in pixels (unlike corner annotations, readable in a GIF)."""
        actor = self.p.add_text(text, position=xy, font_size=max(8, int(points * self.font)),
                                color=color, render=False)
        prop = actor.GetTextProperty()
        prop.SetJustification({"left": 0, "center": 1, "right": 2}[horizontal])
        prop.SetVerticalJustification({"bottom": 0, "center": 1, "top": 2}[vertical])
        return actor

    def close(self):
        self.p.close()


def _clim(values) -> list:
    lo, hi = float(np.min(values)), float(np.max(values))
    if hi - lo < 1e-6 * max(abs(hi), 1.0):
        lo, hi = lo - 0.5, hi + 0.5
    return [lo, hi]


def _title(title: str, time_s) -> str:
    return title if time_s is None else f"{title}    t = {time_s:.2f} s"


def _twist(alpha, relative: bool) -> np.ndarray:
    alpha = np.asarray(alpha, dtype=float)
    return alpha - alpha[0] if relative else alpha


def _save_png(path, image) -> Path:
    import imageio.v2 as imageio
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    imageio.imwrite(str(path), image)
    return path


def _save_gif(path, images, fps) -> Path:
    """Quantise every frame to one palette (of the first, middle and last frames):
    7x faster than imageio's per-frame quantisation."""
    from PIL import Image
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    import matplotlib
    w = images[0].shape[1]
    ramp = matplotlib.colormaps[CMAP](np.linspace(0.0, 1.0, w))[None, :, :3]  # the colour bar's
    ramp = np.repeat((255 * ramp).astype(np.uint8), 40, axis=0)
    sample = np.concatenate([images[k] for k in sorted({0, len(images) // 2, len(images) - 1})]
                            + [ramp])
    palette = Image.fromarray(sample).quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    frames = [Image.fromarray(im).quantize(palette=palette, dither=Image.Dither.NONE)
              for im in images]
    frames[0].save(path, save_all=True, append_images=frames[1:], loop=0,
                   duration=int(round(1000.0 / fps)), optimize=False)
    return path


# -- a fresh interpreter for the drawing --------------------------------------------------
_WORKER = ("import importlib.util, pickle, sys\n"
           "spec = importlib.util.spec_from_file_location('rawehelix_render', sys.argv[1])\n"
           "mod = importlib.util.module_from_spec(spec); spec.loader.exec_module(mod)\n"
           "name, args, kwargs = pickle.load(open(sys.argv[2], 'rb'))\n"
           "getattr(mod, name).__wrapped__(*args, **kwargs)\n")


def _in_clean_process(func):
    """Draw in a fresh interpreter when DOLFINx was loaded before VTK (see
    ``_VTK_AFTER_DOLFINX``); a failed drawing is a warning, never the end of a run."""
    @functools.wraps(func)
    def call(path, *args, **kwargs):
        if pyvista is None:
            return None
        if not _VTK_AFTER_DOLFINX:
            return func(path, *args, **kwargs)
        with tempfile.NamedTemporaryFile(suffix=".pkl", delete=False) as f:
            pickle.dump((func.__name__, (str(path), *args), kwargs), f)
        try:
            env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_"))}
            done = subprocess.run([sys.executable, "-c", _WORKER, __file__, f.name], env=env,
                                  capture_output=True, text=True, timeout=600)
        finally:
            os.unlink(f.name)
        if done.returncode != 0 or not Path(path).exists():
            tail = " ".join(done.stderr.strip().splitlines()[-3:])
            logging.getLogger("rawehelix").warning(
                "picture %s not drawn (exit %s): %s", path, done.returncode, tail)
            return None
        return Path(path)
    return call


# -- public ---------------------------------------------------------------------------------
@_in_clean_process
def helix_png(path, x_m, alpha_rad, tension_N, radius_m: float, title: str, time_s=None,
              reference_m=None, magnification=None, radius_magnification=None,
              reference_label="the reference", relative_twist=False, size=PNG_SIZE):
    """One picture of the helix: rings, tethers, centre line coloured by tension.

    x_m (n, 3) node positions [m], alpha_rad (n,) twist, tension_N (n,) or None
    (plain centre line).  The displacement from ``reference_m`` (n, 3), or the
    deflection from the chord when None, is drawn x ``magnification``
    (automatic when None); both factors are written in the picture.  With
    ``relative_twist`` the rings turn by alpha - alpha(0): the twist without
    the rigid spin.  Returns the path, or None without pyvista."""
    if pyvista is None:
        return None
    x_m = np.asarray(x_m, dtype=float)
    view = View([x_m], radius_m, reference_m, magnification, radius_magnification,
                reference_label)
    scalars = np.zeros(len(x_m)) if tension_N is None else np.asarray(tension_N, dtype=float)
    drawing = _Drawing(view, _clim(scalars), size,
                       "tension T (N)" if tension_N is not None else None)
    try:
        image = drawing.show(x_m, _twist(alpha_rad, relative_twist), scalars,
                             _title(title, time_s), view.caption(None, relative_twist))
    finally:
        drawing.close()
    return _save_png(path, image)


def _pick(frames, count):
    """At most ``count`` frames evenly spread, first and last kept."""
    if len(frames) <= count:
        return list(frames)
    return [frames[int(round(k))] for k in np.linspace(0, len(frames) - 1, count)]


@_in_clean_process
def helix_gif(path, frames, radius_m: float, title: str = "", reference_m=None,
              magnification=None, radius_magnification=None, reference_label="the reference",
              relative_twist=True, size=GIF_SIZE, max_frames: int = GIF_FRAMES, fps: int = 8):
    """An animation from frames [(time_s, x_m, alpha_rad, tension_N), ...].

    At most ``max_frames`` frames (evenly picked), one plotter reused, one
    magnification and colour range for all frames.  ``relative_twist`` (the
    default) turns the rings by alpha - alpha(0): at 120 rpm and a few frames a
    second the rigid spin would only alias.  Returns the path or None."""
    if pyvista is None or not frames:
        return None
    frames = _pick(list(frames), max_frames)
    states = [np.asarray(f[1], dtype=float) for f in frames]
    view = View(states, radius_m, reference_m, magnification, radius_magnification,
                reference_label)
    has_T = frames[0][3] is not None
    clim = _clim(np.concatenate([np.ravel(f[3]) for f in frames])) if has_T else [0.0, 1.0]
    drawing = _Drawing(view, clim, size, "tension T (N)" if has_T else None)
    try:
        images = [drawing.show(x, _twist(f[2], relative_twist),
                               f[3] if has_T else np.zeros(len(x)), _title(title, f[0]),
                               view.caption(None, relative_twist))
                  for f, x in zip(frames, states)]
    finally:
        drawing.close()
    return _save_gif(path, images, fps)


@_in_clean_process
def mode_animation(path, s_m, x0_m, displacement, alpha_rad, radius_m: float, title: str,
                   magnification=None, radius_magnification=None, size=GIF_SIZE,
                   frames: int = MODE_FRAMES, fps: int = 12):
    """A mode shape oscillating about the stationary centre line x0_m (n, 3).

    ``displacement`` (n, 3) has unit maximum amplitude and is drawn as
    ``magnification`` m (automatic: about one drawn ring radius); ``alpha_rad``
    (n,) is the twist of the mode at that amplitude, drawn as given.  The
    centre line is coloured by the local displacement amplitude (0 to 1), or by
    the twist amplitude when nothing moves (torsional modes).
    ``frames`` per cycle.  Returns the path or None."""
    if pyvista is None:
        return None
    x0 = np.asarray(x0_m, dtype=float)
    u = np.asarray(displacement, dtype=float)
    a = np.asarray(alpha_rad, dtype=float)
    base = View([x0], radius_m, x0, 1.0, radius_magnification)
    k = magnification or nice(base.kr * base.radius_m)
    view = View([x0], radius_m, x0, k, base.kr)
    amp = np.linalg.norm(u, axis=1)
    what = (f"mode displacement (max 1) drawn as {k:g} m, twist amplitude "
            f"{np.abs(a).max():.2g} rad")
    if amp.max() > 1e-9:  # coloured by what moves: displacement, else twist
        colour, bar = amp, "displacement amplitude"
    else:
        colour, bar = np.abs(a), "twist amplitude (rad)"
    drawing = _Drawing(view, _clim(np.r_[0.0, colour]), size, bar)
    try:
        images = []
        for phase in np.linspace(0.0, 2 * np.pi, frames, endpoint=False):
            c = math.cos(phase)
            images.append(drawing.show(x0 + c * u, c * a, colour, title, view.caption(what)))
    finally:
        drawing.close()
    del s_m  # the shape is given node by node; s_m is for the caller's labels
    return _save_gif(path, images, fps)
