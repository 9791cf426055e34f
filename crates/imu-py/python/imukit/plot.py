"""Figures of imukit results with matplotlib (an optional extra: ``pip install "imukit[plot]"``).

The figures are those of ``imukit plot`` and ``imukit animate``: the same kinds of table are
recognised from their columns and get the same panels (the layout comes from the Rust core),
drawn here by matplotlib. Every function returns the matplotlib object, for the caller to show,
adjust or save (``fig.savefig("truth.png")``, ``anim.save("body.gif", writer="pillow")``).

Tables, CSV paths and dicts of NumPy arrays keyed by imukit's column names are all accepted.

* :func:`figure` — the default figure of one or more tables or CSV files of one kind (truth,
  IMU readings, navigation output, Allan table, errors); later ones dashed, dotted, … (truth vs estimate).
* :func:`trajectory` — paths in the plane (equal scales) or in 3D, start ● and end ✕ marked.
* :func:`allan` — Allan deviation on log axes.
* :func:`calibration` — a calibration's residuals, as ``imukit calibrate --plot`` draws them.
* :func:`animate` — the body as a box moving and turning along its path, the reference point and
  the IMU point at the lever arm marked, the trail drawn.

>>> import matplotlib; matplotlib.use("Agg")
>>> import imukit, imukit.plot
>>> sim = imukit.simulate({"trajectory": {"type": "builtin", "name": "figure8"}})
>>> fig = imukit.plot.figure(sim.truth)
>>> [ax.get_title() for ax in fig.axes][:3]
['Trajectory', 'Position', 'Velocity']
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import ImuError, Table, _core, quaternion_to_dcm, read_csv
from ._table import TableLike

_D = _core.DEFAULTS  # the library's request defaults, shared with the command line

__all__ = ["figure", "trajectory", "allan", "calibration", "animate", "kind"]

#: A table (anything :data:`imukit.TableLike`) or the path of a CSV file.
TableOrPath = Union[TableLike, str, os.PathLike]
# Line styles of the first, second, … overlaid table (as `imukit plot` draws them).
_STYLES = ("-", "--", ":", "-.")


def _pyplot() -> Any:
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "imukit.plot needs matplotlib: pip install \"imukit[plot]\" (or pip install matplotlib)"
        ) from e
    return plt


def _load(items: Sequence[TableOrPath], labels: Optional[Sequence[str]]) -> list:
    if not items:
        raise ValueError("give at least one table or CSV file")
    if labels is not None and len(labels) != len(items):
        raise ValueError(f"{len(labels)} labels for {len(items)} tables")
    out = []
    for i, item in enumerate(items):
        if isinstance(item, (str, os.PathLike)):
            name, table = Path(item).stem, read_csv(item)
        else:  # a Table, a DataFrame, a structured array or a mapping of arrays
            name, table = f"table {i + 1}", Table.of(item, f"item {i}")
        out.append((labels[i] if labels is not None else name, table))
    return out


def kind(table: Table, source: str = "table") -> str:
    """The kind of an imukit table from its columns: ``truth``, ``imu``, ``navigation``,
    ``orientation``, ``allan``, ``errors`` or ``study``; :class:`ImuError` for anything else."""
    k = _core.table_kind(list(table.columns))
    if k is None:
        raise ImuError(
            f"{source}: unknown kind of table (columns: {', '.join(table.columns)}); imukit plots truth, "
            "IMU readings, navigation output, orientation output, Allan deviation, error and outage-study tables"
        )
    return k


def _kinds(tables: list) -> str:
    first = None
    motion = {"truth", "navigation"}
    for name, t in tables:
        k = kind(t, name)
        if first is not None and k != first and not {k, first} <= motion:
            raise ImuError(f"{name}: is {k}, but the first table is {first}: overlay tables of one kind "
                           "(or truth and navigation output)")
        first = first or k
    assert first is not None
    return first


def _frame(loaded: Sequence[Tuple[str, Table]], nav_frame: Optional[str]) -> str:
    """The frame positions are drawn in: ``nav_frame``, else what the tables' descriptions say,
    else the default; an argument or a table that contradicts another is refused (as ``imukit
    plot`` does with files)."""
    said = [(name, str(t.description["nav_frame"]).upper()) for name, t in loaded
            if t.description.get("nav_frame")]
    for (a, fa), (b, fb) in zip(said, said[1:]):
        if fa != fb:
            raise ImuError(f"nav_frame: the tables disagree: {a} says {fa}, {b} says {fb}")
    if nav_frame is None:
        return said[0][1] if said else _D["nav_frame"]
    if said and nav_frame.upper() != said[0][1]:
        raise ImuError(f"nav_frame: {nav_frame} contradicts {said[0][0]}, whose description says "
                       f"{said[0][1]} (leave the argument out to use it)")
    return nav_frame


def _points(t: Table, nav_frame: str = _D["nav_frame"]) -> np.ndarray:
    """Positions (N, 3) in east, north, up (NED ones turned as ``imukit plot`` turns them)."""
    z = t["pos_z_m"] if "pos_z_m" in t else np.zeros(len(t))
    p = np.ascontiguousarray(np.column_stack([t["pos_x_m"], t["pos_y_m"], z]))
    return _core.points_enu(p, nav_frame)


def trajectory(*tables: TableOrPath, labels: Optional[Sequence[str]] = None, ax: Any = None,
               nav_frame: Optional[str] = None) -> Any:
    """Paths of truth or navigation tables (``pos_*_m``): seen from above with equal scales when
    they stay in a plane, in 3D otherwise; start ● and end ✕ marked; NED paths (``nav_frame``,
    by default what the tables' descriptions say, else ENU) are drawn east, north, up. Returns
    the figure."""
    loaded = _load(tables, labels)
    nav_frame = _frame(loaded, nav_frame)
    paths = [(name, _points(t, nav_frame)) for name, t in loaded]
    three_d = _core.leaves_plane(np.ascontiguousarray(np.vstack([p for _, p in paths])))
    if ax is None:
        fig = _pyplot().figure(figsize=(6.4, 4.8))
        ax = fig.add_subplot(projection="3d" if three_d else None)
    for k, (name, p) in enumerate(paths):
        colour = f"C{k}"
        if three_d:
            ax.plot(p[:, 0], p[:, 1], p[:, 2], color=colour, label=name)
            ax.scatter(*p[0], color=colour, marker="o", s=40)
            ax.scatter(*p[-1], color=colour, marker="x", s=60)
        else:
            ax.plot(p[:, 0], p[:, 1], color=colour, label=name)
            ax.plot(*p[0, :2], color=colour, marker="o", linestyle="none")
            ax.plot(*p[-1, :2], color=colour, marker="x", markersize=9, mew=2, linestyle="none")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if three_d:
        ax.set_zlabel("z (m)")
        ax.set_title("Trajectory")
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title("Trajectory (top view)")
    ax.legend(title="● start  ✕ end", fontsize="small")
    return ax.figure


def allan(tau_s: Union[TableOrPath, np.ndarray], adev: Optional[np.ndarray] = None, *,
          labels: Optional[Sequence[str]] = None, ax: Any = None) -> Any:
    """Allan deviation on log axes (the fitted terms and bands: :func:`imukit.identify`, or
    ``imukit identify --plot``).

    Give ``tau_s`` and ``adev`` ((T,) or (T, k)) as from :func:`imukit.allan_deviation`, or an
    Allan table / CSV (``tau_s, adev_*``) alone. Returns the figure."""
    if adev is None:
        (_, table), = _load([tau_s], None)  # type: ignore[list-item]
        if kind(table) != "allan":
            raise ImuError("allan() needs tau_s and adev, or an Allan table (tau_s, adev_*)")
        cols = [c for c in table.columns if c.startswith("adev_")]
        tau = table["tau_s"]
        curves = np.column_stack([table[c] for c in cols])
        names = list(labels) if labels is not None else [c[len("adev_"):] for c in cols]
    else:
        tau = np.asarray(tau_s, dtype=np.float64)
        curves = np.asarray(adev, dtype=np.float64).reshape(tau.shape[0], -1)
        names = list(labels) if labels is not None else [f"column {k}" for k in range(curves.shape[1])]
    if len(names) != curves.shape[1]:
        raise ValueError(f"{len(names)} labels for {curves.shape[1]} curves")
    if ax is None:
        fig = _pyplot().figure(figsize=(7.5, 5.0))
        ax = fig.add_subplot()
    for k, name in enumerate(names):
        colour = f"C{k}"
        ax.loglog(tau, curves[:, k], "o-", color=colour, markersize=3, label=name)
    ax.set_xlabel("τ (s)")
    ax.set_ylabel("σ(τ) (unit of the column)")
    ax.set_title("Allan deviation")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return ax.figure


def calibration(cal: Any, *, size_in: Optional[Tuple[float, float]] = None,
                dpi: Optional[float] = None) -> Any:
    """The residuals of an :class:`imukit.Calibration` (from :func:`imukit.calibrate`), as
    ``imukit calibrate --plot`` draws them: per rest, gravity's magnitude less the calibrated
    mean reading; per turn, the angle by which the calibrated rate misses the next rest's
    gravity; per magnetometer reading, its distance from the fitted sphere — each panel titled
    with its RMS and the raw readings'. Returns the figure."""
    r = cal.residuals
    panels = [(title, unit, scale, t, raw, done) for title, unit, scale, t, raw, done in (
        ("Accelerometer at the rests, |a| − g", "m/s²", 1.0, "rest_t_s", "accel_raw_m_s2", "accel_m_s2"),
        ("Gyroscope over the turns, gravity missed by", "°", 180.0 / np.pi, "rotation_t_s", "gyro_raw_rad", "gyro_rad"),
        ("Magnetometer, distance from the sphere", "%", 100.0, "mag_t_s", "mag_raw", "mag"),
    ) if len(r.get(t, ())) > 0]
    if not panels:
        raise ImuError("calibration(): the calibration has no residuals to draw")
    plt = _pyplot()
    fig = plt.figure(figsize=size_in or (9.0, 3.0 * len(panels)), dpi=dpi, layout="constrained")
    for k, (title, unit, scale, t, raw, done) in enumerate(panels):
        ax = fig.add_subplot(len(panels), 1, k + 1)
        rms = lambda v: float(np.sqrt(np.mean(np.square(v)))) * scale  # noqa: E731
        ax.plot(r[t], r[done] * scale, "-", color="C0", label="calibrated")
        ax.set_title(f"{title}: RMS {rms(r[done]):.3e} {unit} (raw {rms(r[raw]):.3e})")
        ax.set_xlabel("t (s)")
        ax.set_ylabel(unit)
        ax.grid(True, alpha=0.3)
    return fig


def _study(table: Table, size_in: Optional[Tuple[float, float]], dpi: Optional[float]) -> Any:
    """An outage study's figure, as ``imukit plot study.csv`` draws it: per preset the RMS error
    (solid), the filter's one-sigma (dashed) and the smoothed error (dotted), log scale."""
    plt = _pyplot()
    fig = plt.figure(figsize=size_in or (9.0, 6.0), dpi=dpi, layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    t = table["t_s"]
    presets = [c[: -len("_rms_error_m")] for c in table.columns
               if c.endswith("_rms_error_m") and not c.endswith("_smoothed_rms_error_m")]
    for k, preset in enumerate(presets):
        colour = f"C{k}"
        ax.semilogy(t, table[f"{preset}_rms_error_m"], "-", color=colour, label=preset)
        ax.semilogy(t, table[f"{preset}_sigma_m"], "--", color=colour)
        if f"{preset}_smoothed_rms_error_m" in table:
            ax.semilogy(t, table[f"{preset}_smoothed_rms_error_m"], ":", color=colour)
    ax.set_xlabel("time since the outage began (s)")
    ax.set_ylabel("m (solid: RMS over runs; dashed: filter's 1σ; dotted: smoothed)")
    ax.set_title("Horizontal position error through the GNSS outage")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return fig


def figure(*tables: TableOrPath, labels: Optional[Sequence[str]] = None, nav_frame: Optional[str] = None,
           size_in: Optional[Tuple[float, float]] = None, dpi: Optional[float] = None) -> Any:
    """The default figure of imukit tables or CSV files of one kind (or truth and navigation
    output together): the trajectory and the time-series panels of ``imukit plot``, later tables
    dashed, dotted, …; NED paths (``nav_frame``, by default what the tables' descriptions say,
    else ENU) are drawn east, north, up. ``size_in`` (width,
    height in inches) and ``dpi`` as ``imukit plot --size --dpi``; the title names the tables,
    their kind and the frame. Returns the figure."""
    loaded = _load(tables, labels)
    nav_frame = _frame(loaded, nav_frame)
    k = _kinds(loaded)
    if k == "allan":
        if len(loaded) > 1:
            raise ImuError("overlay Allan curves by passing tau_s and a (T, k) adev to allan()")
        return allan(loaded[0][1], labels=None)
    if k == "study":
        if len(loaded) > 1:
            raise ImuError("an outage study is drawn alone: give one study table")
        return _study(loaded[0][1], size_in, dpi)
    panels = [p for p in _core.figure_panels(k)
              if any(c in t for _, t in loaded for c, _ in p[3])]
    with_path = k in ("truth", "navigation")
    cells = len(panels) + int(with_path)
    ncols = 2 if cells > 3 else 1
    nrows = -(-cells // ncols)
    plt = _pyplot()
    fig = plt.figure(figsize=size_in or (5.6 * ncols, 3.2 * nrows), dpi=dpi, layout="constrained")
    fig.suptitle(f"{', '.join(n for n, _ in loaded)} ({k}) — {nav_frame}")
    index = 1
    if with_path:
        points = np.vstack([_points(t, nav_frame) for _, t in loaded])
        three_d = _core.leaves_plane(np.ascontiguousarray(points))
        ax = fig.add_subplot(nrows, ncols, index, projection="3d" if three_d else None)
        trajectory(*[t for _, t in loaded], labels=[n for n, _ in loaded], ax=ax, nav_frame=nav_frame)
        index += 1
    for title, y_label, scale, columns, envelopes in panels:
        ax = fig.add_subplot(nrows, ncols, index)
        index += 1
        for f, (name, t) in enumerate(loaded):
            for c_k, (column, label) in enumerate(columns):
                if column in t and "t_s" in t:
                    text = f"{label} ({name})" if len(loaded) > 1 else label
                    ax.plot(t["t_s"], t[column] * scale, color=f"C{c_k}", linestyle=_STYLES[f % 4], label=text)
            # ±3σ of a fused estimate's errors (its one-sigma columns), dotted in the line's colour.
            for sigma, c_k in envelopes:
                if sigma in t and "t_s" in t:
                    three = 3.0 * t[sigma] * scale
                    ax.plot(t["t_s"], three, color=f"C{c_k}", linestyle=":", label=f"±3σ {columns[c_k][1]}")
                    ax.plot(t["t_s"], -three, color=f"C{c_k}", linestyle=":")
        ax.set_title(title)
        ax.set_xlabel("t (s)")
        ax.set_ylabel(y_label)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small", loc="upper right")
    return fig


def animate(truth: TableLike, *, body_m: Optional[Sequence[float]] = None,
            lever_arm_m: Sequence[float] = (0.0, 0.0, 0.0), fps: float = _D["animation_fps"],
            speed: Optional[float] = None, nav_frame: Optional[str] = None) -> Any:
    """The body moving along its path, as ``imukit animate`` draws it: a box of ``body_m``
    (length, width, height along body x, y, z; by default a tenth of the path's extent long)
    turned by the truth's attitude, its nose face red, the reference point (yellow) and the IMU
    point at ``lever_arm_m`` (violet), the trail blue. ``fps`` frames per second, ``speed``
    seconds of motion per second (by default the animation lasts 4 to 12 s). A NED truth
    (``nav_frame``, by default what its description says, else ENU) is drawn turned into east,
    north, up (the body axes stay those of the data).

    Returns a ``matplotlib.animation.FuncAnimation``; ``anim.save("body.gif", writer="pillow")``
    writes it."""
    from matplotlib.animation import FuncAnimation

    (name, t), = _load([truth], None)
    nav_frame = _frame([(name, t)], nav_frame)
    for c in ("t_s", "pos_x_m", "pos_y_m", "pos_z_m", "q_w", "q_x", "q_y", "q_z"):
        if c not in t:
            raise ImuError(f"{name}: no {c} column: animate needs a truth table (t_s, pos_*_m, q_*)")
    lever = np.asarray(lever_arm_m, dtype=np.float64)
    if lever.shape != (3,) or not np.all(np.isfinite(lever)):
        raise ValueError("lever_arm_m must be 3 finite numbers")
    frames, speed_used = _core.frame_plan(np.ascontiguousarray(t["t_s"]), float(fps), speed)
    q_nb = np.ascontiguousarray(np.column_stack([t["q_w"], t["q_x"], t["q_y"], t["q_z"]]))
    position = np.ascontiguousarray(np.column_stack([t["pos_x_m"], t["pos_y_m"], t["pos_z_m"]]))
    # Drawn in east, north, up; the body axes stay those of the data (the same turn as imukit animate).
    p, q = _core.poses_enu(position, q_nb, nav_frame)
    extent = float(np.max(np.ptp(p, axis=0)))
    body = np.asarray(_core.default_body_m(extent) if body_m is None else body_m, dtype=np.float64)
    if body.shape != (3,) or not np.all(body > 0):
        raise ValueError("body_m must be 3 positive numbers (length, width, height)")
    dcm = quaternion_to_dcm(q[frames])
    corners, edges, nose = _core.animation_scene([float(b) for b in body])

    fig = _pyplot().figure(figsize=(6.4, 4.8))
    ax = fig.add_subplot(projection="3d")
    pad = float(max(np.max(body), np.max(np.abs(lever))))
    lo, hi = p.min(axis=0) - pad, p.max(axis=0) + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.plot(p[:, 0], p[:, 1], p[:, 2], color="0.75", linewidth=1)
    (trail,) = ax.plot([], [], [], color="C0", linewidth=2)
    box = [ax.plot([], [], [], color="C3", linewidth=2)[0] for _ in edges]
    (face,) = ax.plot([], [], [], color="C3", linewidth=4, alpha=0.5)
    (ref,) = ax.plot([], [], [], "o", color="#e6be00", markersize=7)
    (imu,) = ax.plot([], [], [], "o", color="C4", markersize=6)
    title = ax.set_title("")

    def draw(k: int):
        i = frames[k]
        c = p[i] + corners @ dcm[k].T
        for line, (a, b) in zip(box, edges):
            line.set_data_3d(c[[a, b], 0], c[[a, b], 1], c[[a, b], 2])
        ring = nose + nose[:1]
        face.set_data_3d(c[ring, 0], c[ring, 1], c[ring, 2])
        trail.set_data_3d(p[: i + 1, 0], p[: i + 1, 1], p[: i + 1, 2])
        ref.set_data_3d([p[i, 0]], [p[i, 1]], [p[i, 2]])
        m = p[i] + dcm[k] @ lever
        imu.set_data_3d([m[0]], [m[1]], [m[2]])
        title.set_text(f"t = {t['t_s'][i]:.2f} s · {speed_used:g}× real time")
        return [trail, face, ref, imu, *box]

    return FuncAnimation(fig, draw, frames=len(frames), interval=1000.0 / fps, blit=False)
