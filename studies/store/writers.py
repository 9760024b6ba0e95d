"""Writers: summary.json, PNG figures and XDMF files.  Writers never solve.

Every function here runs on one rank (the caller picks rank 0)."""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from rawehelix.errors import OutputFault


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def digest(data) -> str:
    """A short hash of JSON-able data: the fingerprint that keeps results of
    another scene or discretisation apart."""
    text = json.dumps(data, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


#: a temporary file of write_text or write_npz: ``.NAME.<random>.tmp`` next to NAME
#: (``.NAME.<pid>.tmp.npz``: write_npz before issue 27); a killed run leaves it
#: behind and :func:`remove_stale_temps` takes it away when the folder is locked
TEMP_SUFFIXES = (".tmp", ".tmp.npz")


def _temp(path: Path) -> tuple[int, str]:
    path.parent.mkdir(parents=True, exist_ok=True)
    return tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_SUFFIXES[0])


def _atomic(path: Path, fill) -> Path:
    """``fill(file)`` writes a temporary file beside ``path``, which then replaces
    ``path``: a reader never sees half a file.  On any failure (a full disk,
    Ctrl-C) the temporary file is removed; an OSError of the disk becomes an
    :class:`OutputFault` naming ``path``."""
    path = Path(path)
    tmp = None
    try:
        fd, tmp = _temp(path)
        os.chmod(tmp, 0o644)  # mkstemp makes it private; a results file is for everyone to read
        with os.fdopen(fd, "wb") as f:
            fill(f)
        os.replace(tmp, path)
        tmp = None
    except OSError as err:
        raise OutputFault.of(err, path) from err
    finally:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass
    return path


def write_text(path: Path, text: str) -> Path:
    """Write a text file atomically (:func:`_atomic`)."""
    return _atomic(path, lambda f: f.write(text.encode("utf-8")))


def append_line(path: Path, line: str) -> Path:
    """Append one line to a log file in one write() (a full disk: no half line
    is left for the next run to append to; :class:`OutputFault`)."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, (line.rstrip("\n") + "\n").encode("utf-8"))
        finally:
            os.close(fd)
    except OSError as err:
        raise OutputFault.of(err, path) from err
    return path


def remove_stale_temps(folder: Path) -> list[Path]:
    """Remove the temporary files (TEMP_SUFFIXES) that a killed run left in
    ``folder`` and its subfolders (points/, window<k>/; no deeper: ``-o .`` must
    not walk a whole tree); only for the holder of the folder's lock.  Returns them."""
    removed = []
    folder = Path(folder)
    for path in [*folder.glob(".*"), *folder.glob("*/.*")]:
        if path.is_file() and path.name.endswith(TEMP_SUFFIXES) and path.name.count(".") >= 3:
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed


def file_sha256(path: Path) -> str:
    """The SHA-256 of a file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_json(path: Path, data: dict) -> Path:
    """Write JSON atomically (:func:`write_text`)."""
    return write_text(path, json.dumps(_jsonable(data), indent=2) + "\n")


#: a header's record of the scene's keys (:func:`scene_keys`): written for the refusal to
#: say what changed, not compared (a folder written before it had none)
SCENE_KEYS = "scene_keys"


def scene_keys(data: dict, prefix: str = "") -> dict:
    """The scene's dict (``Parameters.as_dict``, or a fingerprint's part of it) as dotted
    keys: {"helix.EI_Nm2": 4381.0, ...}."""
    out = {}
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(scene_keys(value, name + "."))
        else:
            out[name] = _jsonable(value)
    return out


def changed(old: dict, new: dict, option_of: dict | None = None, most: int = 4) -> list[str]:
    """What differs between a folder's header ``old`` and a run's ``new``: each header
    key by its option (``option_of``), and the scene's keys with their old and new values
    where both headers record them (:data:`SCENE_KEYS`), the first ``most`` of them."""
    option_of = option_of or {}
    new = _jsonable(new)
    out = [option_of.get(k, k) for k in new if k != SCENE_KEYS and old.get(k) != new.get(k)]
    a, b = old.get(SCENE_KEYS), new.get(SCENE_KEYS)
    if a is not None and b is not None:
        keys = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
        out += [f"{k} {a.get(k, 'absent')} -> {b.get(k, 'absent')}" for k in keys[:most]]
        if len(keys) > most:
            out.append(f"{len(keys) - most} more scene keys")
    return out


def _compared(header):
    return {k: v for k, v in header.items() if k != SCENE_KEYS} if isinstance(header, dict) \
        else header


def claim_directory(path: Path, header: dict, comm) -> dict | None:
    """A run's header file ``path``: written on rank 0 if absent; if it holds
    another header, that one is returned on every rank (the caller refuses the
    directory), else None.  A header file that is not JSON (damaged outside a
    run: its writes are atomic) is set aside with a warning and written again.
    Collective; the caller holds the folder's lock (studies/store/outdir_lock.py)."""
    old = None
    if comm.rank == 0:
        path = Path(path)
        stored = None
        if path.exists():
            try:
                stored = json.loads(path.read_text())
            except (ValueError, UnicodeDecodeError) as err:
                from rawehelix.studies.store.quarantine import set_aside
                set_aside([path], path.parent, f"not JSON ({err})",
                                      then="written again")
        if stored is None:
            write_json(path, header)
        elif _compared(stored) != _compared(_jsonable(header)):
            old = stored if isinstance(stored, dict) else {"header": stored}
    return comm.bcast(old, root=0)


def summary_and_figure(outdir, rank: int, summary: dict, figure) -> Path:
    """On rank 0: ``outdir``/summary.json and ``figure(outdir)`` (a callable that
    writes the study's figure there); other ranks write nothing.  ``outdir``."""
    outdir = Path(outdir)
    if rank != 0:
        return outdir
    outdir.mkdir(parents=True, exist_ok=True)
    write_json(outdir / "summary.json", summary)
    figure(outdir)
    return outdir


def _finish(fig, path: Path, title: str, dpi: int = 110) -> Path:
    """Title, layout, write the PNG and free the figure."""
    import matplotlib.pyplot as plt
    fig.suptitle(title)
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=dpi)
    except OSError as err:
            raise OutputFault.of(err, path) from err
    finally:
        plt.close(fig)
    return path


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _deflection(x_m):
    """Signed in-plane distance from the chord and out-of-plane y, along the chord."""
    chord = x_m[-1] - x_m[0]
    e = chord / np.linalg.norm(chord)
    normal = np.cross(e, [0.0, 1.0, 0.0])  # in the x-z plane, normal to the chord
    d = x_m - x_m[0]
    return d @ e, d @ normal, d[:, 1]


def centre_line_png(path: Path, s_m, x_m, tension_s_m, tension_N, title: str,
                    reference_x_m=None, reference_label="shooting") -> Path:
    """Three panels: the centre line in the x-z plane (z down, as in the paper),
    its deflection from the chord (the sag is too small to see in the first),
    and the tension along s."""
    plt = _pyplot()
    fig, (ax0, ax1, ax2) = plt.subplots(1, 3, figsize=(15, 4.2))
    ax0.plot(x_m[:, 0], x_m[:, 2], "-", lw=2, label="FE centre line")
    ax0.plot([x_m[0, 0], x_m[-1, 0]], [x_m[0, 2], x_m[-1, 2]], "k:", lw=1, label="chord")
    ax0.invert_yaxis()
    ax0.set_xlabel("x [m]")
    ax0.set_ylabel("z [m] (down)")
    ax0.set_aspect("equal", adjustable="datalim")
    ax0.legend(loc="best")
    ax0.set_title("centre line")
    along, normal, y = _deflection(x_m)
    ax1.plot(along, 1e3 * normal, "-", lw=2, label="FE, in plane")
    if np.any(np.abs(y) > 1e-9):
        ax1.plot(along, 1e3 * y, "-", lw=1, label="FE, out of plane (y)")
    if reference_x_m is not None:
        r_along, r_normal, _ = _deflection(reference_x_m)
        ax1.plot(r_along, 1e3 * r_normal, "--", lw=1.5, label=reference_label)
    ax1.set_xlabel("distance along the chord [m]")
    ax1.set_ylabel("deflection from the chord [mm]")
    ax1.set_title("deflection (normal to the chord)")
    ax1.grid(True, alpha=0.3)
    ax1.legend(loc="best")
    ax2.plot(tension_s_m, tension_N, "-")
    ax2.set_xlabel("s [m]")
    ax2.set_ylabel("tension T [N]")
    ax2.set_title("tension, Eq. (22)")
    ax2.grid(True, alpha=0.3)
    return _finish(fig, path, title, dpi=110)


def centre_line_xdmf(path: Path, x_m, point_data: dict) -> Path:
    """The deformed centre line as a polyline in 3D with point data, for ParaView."""
    import meshio
    n = len(x_m)
    cells = [("line", np.stack([np.arange(n - 1), np.arange(1, n)], axis=1))]
    mesh = meshio.Mesh(np.asarray(x_m, dtype=float), cells,
                       point_data={k: np.asarray(v, dtype=float) for k, v in point_data.items()})
    meshio.write(str(path), mesh)
    return path


def mode_shapes_png(path: Path, s_m, shapes: dict, title: str) -> Path:
    """One panel per mode: displacement along the chord, normal to it in the x-z
    plane and along y, and the twist, against the arc length.

    ``shapes``: label -> (u_chord, u_normal, u_y, alpha) arrays over ``s_m``."""
    plt = _pyplot()
    n = max(len(shapes), 1)
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.5 * cols, 3.2 * rows), squeeze=False)
    for ax, (label, (ut, un, uy, alpha)) in zip(axes.ravel(), shapes.items()):
        ax.plot(s_m, ut, label="along chord")
        ax.plot(s_m, un, label="normal, x-z plane")
        ax.plot(s_m, uy, label="y")
        ax.plot(s_m, alpha, "k--", label="twist alpha (own scale)")
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("s [m]")
        ax.grid(True, alpha=0.3)
    for ax in axes.ravel()[len(shapes):]:
        ax.axis("off")
    axes.ravel()[0].legend(loc="best", fontsize=8)
    return _finish(fig, path, title, dpi=120)


def dynamics_png(path: Path, rows: np.ndarray, target_rpm: float, title: str) -> Path:
    """Fig. 6 of the paper: (a) spins at s = 0, ~L0/2, L0 and the target, (b) ground
    torque, (c) tensions at the ends.  ``rows`` as in studies.simulate.COLUMNS."""
    plt = _pyplot()
    t = rows[:, 0]
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    for k, (style, label) in enumerate(((":", "s = 0"), ("--", "s = L0/2"), ("-", "s = L0"))):
        ax[0].plot(t, rows[:, 1 + k], style, label=label)
    ax[0].axhline(target_rpm, color="k", lw=2.5, alpha=0.5, label="target")
    ax[0].set_ylabel("spin dα/dt [rpm]")
    ax[0].legend(loc="lower right")
    ax[1].plot(t, rows[:, 4], "-")
    ax[1].set_ylabel("ground torque M0 [Nm]")
    ax[2].plot(t, rows[:, 5], "-", label="s = 0")
    ax[2].plot(t, rows[:, 6], "--", label="s = L0")
    ax[2].set_ylabel("tension T [N]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(loc="best")
    for a in ax:
        a.grid(True, alpha=0.3)
    return _finish(fig, path, title, dpi=110)


def write_npz(path: Path, arrays: dict) -> Path:
    """Write arrays to an .npz atomically (:func:`_atomic`).  The archive is built in
    memory and written in one piece: np.savez straight into the file leaves its
    ZipFile unclosed when a write fails (a full disk), and the ZipFile's __del__
    then prints ``Exception ignored`` at exit after the run's one-line message."""
    import io

    def fill(f):
        buffer = io.BytesIO()
        np.savez(buffer, **arrays)
        f.write(buffer.getbuffer())
    return _atomic(path, fill)


#: the members' fields of a frame (studies/analysis/structure_limits.py::Tracker.profile)
MEMBER_FIELDS = ("member_force_min_N", "member_force_max_N", "moment_ratio")


def frames_xdmf(path: Path, frames) -> Path:
    """The moving centre line with its fields, one XDMF step per frame
    (``simulate.Frame``: t_s, s_m, x_m, tension_N, twist, alpha, spin and, where
    present, :data:`MEMBER_FIELDS`)."""
    from rawehelix.studies.store.xdmf_series import PolylineSeries
    series = PolylineSeries(path)
    try:
        for f in frames:
            data = {"s_m": f.s_m, "tension_N": f.tension_N, "twist_rad_per_m": f.twist_rad_per_m,
                    "alpha_rad": f.alpha_rad, "spin_rpm": f.spin_rpm}
            data.update({k: getattr(f, k) for k in MEMBER_FIELDS if getattr(f, k) is not None})
            series.write(f.t_s, f.x_m, data)
    finally:
        series.close()
    return Path(path)


def members_png(path: Path, history, frames, breaking_N, title: str) -> Path:
    """The [section] members' forces (the limits block, studies/analysis/structure_limits.py):
    (a) the smallest and largest member force against t (``history``: rows t [s],
    min, max [N]) with the slack line (0) and the breaking force (if set); (b) the
    smallest member force over (s, t) from the frames (``simulate.Frame``)."""
    plt = _pyplot()
    history = np.asarray(history, dtype=float)
    frames = [f for f in frames if f.member_force_min_N is not None]
    fig, ax = plt.subplots(2, 1, figsize=(7, 7.5))
    ax[0].plot(history[:, 0], history[:, 2], "-", label="largest member force")
    ax[0].plot(history[:, 0], history[:, 1], "-", label="smallest member force")
    ax[0].axhline(0.0, color="k", lw=1.5, ls="--", label="slack (0 N)")
    if breaking_N is not None:
        ax[0].axhline(breaking_N, color="r", lw=1.5, ls="--", label="breaking force")
    ax[0].set_xlabel("t [s]")
    ax[0].set_ylabel("member force [N]")
    ax[0].legend(loc="best", fontsize=8)
    ax[0].grid(True, alpha=0.3)
    if len(frames) > 1:
        t = np.array([f.t_s for f in frames])
        f_min = np.array([f.member_force_min_N for f in frames])
        bound = max(np.abs(f_min).max(), 1e-12)  # centred on the slack line
        mesh = ax[1].pcolormesh(frames[0].s_m, t, f_min, shading="nearest", cmap="RdBu",
                                vmin=-bound, vmax=bound)
        fig.colorbar(mesh, ax=ax[1], label="smallest member force [N]")
        ax[1].set_xlabel("s [m]")
        ax[1].set_ylabel("t [s]")
        ax[1].set_title("smallest member force over (s, t) (red: slack)", fontsize=10)
    else:
        ax[1].axis("off")
    return _finish(fig, path, title, dpi=110)
