"""Figures the project writes, in one style: the spectrogram (velocity and Doppler axes), the
range-time map, experiment confusion matrices and feature scatter plots.

Also the FMCW products: range-Doppler maps and point clouds.

Every figure goes through :func:`style` (one set of matplotlib rc parameters: fonts, sizes,
a colour-blind-safe line cycle) and :func:`save` (a caption below the axes, one resolution).
Power maps use perceptually uniform colour maps (``viridis`` by default, see
:class:`~mdframework.settings.FiguresConfig`). :func:`draw_spectrogram` draws a spectrogram into
given axes, so multi-panel figures (the docs figures, the motion preview) look like a run's own
``spectrogram.png``. :func:`run_caption` builds the title and caption of a run's figures from its
metadata and resolved config.

matplotlib is imported inside the functions that draw, never at import time.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: Default dynamic range of spectrogram and range-time images [dB below the peak].
DYNAMIC_RANGE_DB = 40.0
#: Default colour map of power images (perceptually uniform).
COLORMAP = "viridis"
#: Resolution of every saved figure [dots per inch].
DPI = 110

_RC: dict[str, Any] = {
    "font.size": 9.0,
    "axes.titlesize": 10.0,
    "axes.labelsize": 9.0,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "legend.fontsize": 8.0,
    "figure.dpi": DPI,
    "savefig.dpi": DPI,
    "image.cmap": COLORMAP,
    "image.interpolation": "nearest",
    "axes.grid": False,
    "figure.facecolor": "white",
    "pdf.fonttype": 42,  # TrueType, not Type 3 (which publishers refuse)
    "svg.fonttype": "none",  # text as text
}
_CAPTION_SIZE = 7.5


def _pyplot() -> Any:
    """``matplotlib.pyplot``, on the Agg backend when this process has not imported pyplot
    yet (the command line); a script or notebook that plots with pyplot keeps its backend."""
    import sys

    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


@contextmanager
def _rc_context() -> Iterator[None]:
    """The project's rc parameters, without importing pyplot."""
    import matplotlib
    from matplotlib import style as mpl_style

    rc: Any = dict(_RC)
    rc["axes.prop_cycle"] = mpl_style.library["tableau-colorblind10"]["axes.prop_cycle"]
    with matplotlib.rc_context(rc):
        yield


@contextmanager
def style() -> Iterator[Any]:
    """The project's figure style as a matplotlib rc context; yields ``matplotlib.pyplot``.

    Use it around any figure the project writes (docs scripts included)::

        with style() as plt:
            fig, ax = plt.subplots(layout="constrained")
    """
    plt = _pyplot()
    with _rc_context():
        yield plt


def subplots(
    *args: Any, figsize: tuple[float, float], layout: Any = "constrained", **kwargs: Any
) -> tuple[Any, Any]:
    """Like ``pyplot.subplots``, but a bare :class:`matplotlib.figure.Figure` that pyplot never
    sees: no figure manager, no global state and no pyplot import (so a run's figures cost less
    start-up). Use it under the project's style; save it with :func:`save`."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout=layout)
    return fig, fig.subplots(*args, **kwargs)


def wrap_caption(caption: str, fig: Any, fontsize: float = _CAPTION_SIZE) -> str:
    """``caption`` with its lines broken at spaces so that each fits the width of ``fig`` (less
    the 1 % margins :func:`save` leaves) in ``fontsize`` points of the current style's font,
    measured by matplotlib's Agg renderer; a word wider than that stays whole on its line."""
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties

    renderer = RendererAgg(1, 1, fig.dpi)  # type: ignore[no-untyped-call]
    prop = FontProperties(size=fontsize)
    room = 0.98 * fig.get_figwidth() * fig.dpi

    def width(text: str) -> float:
        size = renderer.get_text_width_height_descent(  # type: ignore[no-untyped-call]
            text, prop, ismath=False
        )
        return float(size[0])

    out = []
    for line in caption.split("\n"):
        current = ""
        for word in line.split(" "):
            trial = f"{current} {word}" if current else word
            if current and width(trial) > room:
                out.append(current)
                current = word
            else:
                current = trial
        out.append(current)
    return "\n".join(out)


def save(
    fig: Any, path: Path, caption: str = "", *, title: str = "", also: Sequence[str] = ()
) -> None:
    """Save ``fig`` (made with constrained layout under :func:`style`, or by :func:`subplots`)
    with ``title`` over its first axes and ``caption`` set in small type below the axes, then
    close it. ``also``: more formats to write the same figure in, beside ``path`` with their
    suffix (``"pdf"``, ``"svg"``: vector, fonts embedded as TrueType or kept as text)."""
    if title:
        fig.axes[0].set_title(title)
    if caption:
        caption = wrap_caption(caption, fig)
        lines = caption.count("\n") + 1
        height = fig.get_figheight()
        bottom = min(0.4, (lines * _CAPTION_SIZE * 1.45 + 6) / 72 / height)
        engine = fig.get_layout_engine()
        if engine is not None and hasattr(engine, "set"):
            engine.set(rect=(0.0, bottom, 1.0, 1.0 - bottom))
        fig.text(0.01, 0.01, caption, ha="left", va="bottom", fontsize=_CAPTION_SIZE, color="0.25")
    fig.savefig(path)
    for suffix in also:
        fig.savefig(Path(path).with_suffix(f".{suffix}"))
    if getattr(fig.canvas, "manager", None) is not None:  # made by pyplot: release it there
        _pyplot().close(fig)


def velocity_limits(
    spectrogram_db: NDArray[np.floating[Any]],
    velocity: NDArray[np.float64],
    span: str | float = "auto",
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
) -> tuple[float, float]:
    """Velocity-axis limits [m/s] of a spectrogram display.

    ``span``: ``"full"``: the whole unambiguous axis; a number ``v``: ``(-v, v)``, clipped to the
    axis; ``"auto"``: the velocities where the power is. Auto takes the velocity bins in which
    any frame comes within ``dynamic_range_db`` of the peak (the bins the image shows in
    colour), widens their extent (zero always included) by a tenth of itself plus two bins on
    each side, and clips it to the axis. ``spectrogram_db`` (n_doppler, n_frames) [dB re peak];
    ``velocity`` (n_doppler,) ascending [m/s].
    """
    dv = float(velocity[1] - velocity[0]) if velocity.size > 1 else 1.0
    lo_axis, hi_axis = float(velocity[0]) - dv / 2, float(velocity[-1]) + dv / 2
    if span == "full":
        return lo_axis, hi_axis
    if not isinstance(span, str):
        return max(lo_axis, -float(span)), min(hi_axis, float(span))
    if span != "auto":
        raise ValueError(f"velocity span must be 'auto', 'full' or a number, got {span!r}")
    peak = np.max(spectrogram_db, axis=1)
    shown = velocity[peak >= np.max(peak) - dynamic_range_db]
    lo, hi = min(0.0, float(shown.min())), max(0.0, float(shown.max()))
    pad = 0.1 * (hi - lo) + 2 * dv
    return max(lo_axis, lo - pad), min(hi_axis, hi + pad)


#: Cells of a dB map drawn across at most (an 8 inch figure at :data:`DPI` has 880
#: pixels across): a longer map is max-pooled, each drawn cell the strongest of the cells it
#: covers. A 300 s spectrogram (22,500 frames) took 1.5 GiB and 14 s to draw whole.
MAX_IMAGE_CELLS = 1024


def _pooled(db: NDArray[np.floating[Any]], axis: int) -> NDArray[np.floating[Any]]:
    """``db`` with axis ``axis`` max-pooled to at most :data:`MAX_IMAGE_CELLS` cells (groups of
    ``k`` cells, the last group what is left), without copying ``db``."""
    n = db.shape[axis]
    k = -(-n // MAX_IMAGE_CELLS)
    if k == 1:
        return db
    whole = (n // k) * k  # at least k: k <= n
    head = db.swapaxes(0, axis)[:whole]
    groups = head.reshape(whole // k, k, *head.shape[1:]).max(axis=1)
    if whole < n:
        rest = db.swapaxes(0, axis)[whole:].max(axis=0, keepdims=True)
        groups = np.concatenate([groups, rest])
    return np.asarray(groups.swapaxes(0, axis))


def _power_image(
    ax: Any,
    db: NDArray[np.floating[Any]],
    across: NDArray[np.float64],
    up: NDArray[np.float64],
    dynamic_range_db: float,
    colormap: str,
    lone_width: float = 1.0,
) -> Any:
    """Draw a dB map ``db`` (len(up), len(across)) into ``ax``, each cell centred on its
    coordinates (``across``, ``up``: evenly spaced, ascending), the top ``dynamic_range_db``
    in colour, max-pooled to :data:`MAX_IMAGE_CELLS` cells across (the rows stay: a velocity
    span may show a few of them); a lone cell across is ``lone_width`` wide. Returns the image
    (for a colour bar)."""
    da = float(across[1] - across[0]) if across.size > 1 else lone_width
    du = float(up[1] - up[0]) if up.size > 1 else 1.0
    extent = (across[0] - da / 2, across[-1] + da / 2, up[0] - du / 2, up[-1] + du / 2)
    peak = float(np.max(db))
    return ax.imshow(
        _pooled(db, 1),
        origin="lower",
        aspect="auto",
        extent=extent,
        cmap=colormap,
        vmin=peak - dynamic_range_db,
        vmax=peak,
        interpolation="nearest",
    )


def draw_spectrogram(
    ax: Any,
    spectrogram_db: NDArray[np.floating[Any]],
    time: NDArray[np.float64],
    velocity: NDArray[np.float64],
    *,
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
    velocity_span: str | float = "auto",
    colormap: str = COLORMAP,
) -> Any:
    """Draw a spectrogram into ``ax``: time [s] across, radial velocity [m/s] up (positive =
    approaching), the top ``dynamic_range_db`` in colour. Returns the image (for a colour bar).
    ``spectrogram_db`` (n_doppler, n_frames) [dB re peak]; ``time`` (n_frames,) [s];
    ``velocity`` (n_doppler,) ascending [m/s]. A lone frame spans its window, from the
    record's start to twice its time (its window's centre)."""
    t0 = float(time[0]) if time.size else 0.0
    lone = 2.0 * t0 if t0 > 0 else 1.0
    im = _power_image(ax, spectrogram_db, time, velocity, dynamic_range_db, colormap, lone)
    ax.set_ylim(*velocity_limits(spectrogram_db, velocity, velocity_span, dynamic_range_db))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("radial velocity [m/s] (+ approaching)")
    return im


def plot_spectrogram(
    path: Path,
    spectrogram_db: NDArray[np.floating[Any]],
    time: NDArray[np.float64],
    velocity: NDArray[np.float64],
    doppler: NDArray[np.float64],
    *,
    title: str = "",
    caption: str = "",
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
    velocity_span: str | float = "auto",
    colormap: str = COLORMAP,
) -> None:
    """Save a spectrogram image: time [s] across, radial velocity [m/s] up (positive =
    approaching) with Doppler [Hz] on the right-hand axis; see :func:`draw_spectrogram`."""
    with _rc_context():
        fig, ax = subplots(figsize=(8, 4.5), layout="constrained")
        im = draw_spectrogram(
            ax,
            spectrogram_db,
            time,
            velocity,
            dynamic_range_db=dynamic_range_db,
            velocity_span=velocity_span,
            colormap=colormap,
        )
        ratio = float(doppler[-1] / velocity[-1]) if velocity[-1] != 0 else 1.0
        sec = ax.secondary_yaxis("right", functions=(lambda v: v * ratio, lambda f: f / ratio))
        sec.set_ylabel("Doppler [Hz]")
        fig.colorbar(im, ax=ax, pad=0.02, label="power [dB re peak]")
        save(fig, path, caption, title=title)


def plot_range_time(
    path: Path,
    range_time_db: NDArray[np.floating[Any]],
    time: NDArray[np.float64],
    ranges: NDArray[np.float64],
    *,
    title: str = "",
    caption: str = "",
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
    colormap: str = COLORMAP,
) -> None:
    """Save a range-time map: time [s] across, range [m] up, |compressed output|^2 in dB re
    peak. ``range_time_db`` (n_slow, n_range); ``time`` (n_slow,) [s]; ``ranges`` (n_range,)
    [m]."""
    with _rc_context():
        fig, ax = subplots(figsize=(8, 4), layout="constrained")
        im = _power_image(ax, range_time_db.T, time, ranges, dynamic_range_db, colormap)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("range [m]")
        fig.colorbar(im, ax=ax, label="compressed power [dB re peak]")
        save(fig, path, caption, title=title)


def plot_confusion(
    path: Path,
    classes: list[str],
    mean: NDArray[np.float64],
    std: NDArray[np.float64] | None,
    *,
    title: str = "",
    caption: str = "",
    also: Sequence[str] = (),
) -> None:
    """Save a row-normalised confusion matrix (true class down, predicted across); ``mean``
    and ``std`` (n_classes, n_classes) rates in [0, 1] (a NaN row: a class not evaluated,
    shown as n/a). ``also``: more formats, as :func:`save`'s."""
    n = len(classes)
    with _rc_context():
        fig, ax = subplots(figsize=(1.3 * n + 2.5, 1.1 * n + 1.8), layout="constrained")
        from matplotlib import colormaps

        cmap = colormaps["cividis"]
        im = ax.imshow(mean, cmap=cmap, vmin=0.0, vmax=1.0)
        for i in range(n):
            for j in range(n):
                if np.isnan(mean[i, j]):  # a class the experiment could not evaluate
                    text = "n/a\n(not evaluated)" if j == 0 else "n/a"
                else:
                    text = f"{mean[i, j]:.2f}" + (f"\n±{std[i, j]:.2f}" if std is not None else "")
                ax.text(
                    j,
                    i,
                    text,
                    ha="center",
                    va="center",
                    color="white" if mean[i, j] <= 0.6 else "black",  # NaN: on white
                )
        ax.set_xticks(range(n), classes, rotation=30, ha="right")
        ax.set_yticks(range(n), classes)
        ax.set_xlabel("predicted")
        ax.set_ylabel("true")
        fig.colorbar(im, ax=ax, label="rate")
        save(fig, path, caption, title=title, also=also)


def scatter_marks(
    x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The distinct points of ``(x, y)`` (n,) and how many records each stands for: ``(xs, ys,
    counts)``, each (n_distinct,), in first-seen order. Features of coarse Doppler bins (a
    frame-based sensor's, RadHAR's) put many records on one point."""
    xy = np.column_stack([x, y])
    unique, first, counts = np.unique(xy, axis=0, return_index=True, return_counts=True)
    order = np.argsort(first, kind="stable")
    return unique[order, 0], unique[order, 1], counts[order].astype(np.int64)


def plot_feature_scatter(
    path: Path,
    x: NDArray[np.float64],
    y: NDArray[np.float64],
    labels: NDArray[Any],
    groups: NDArray[Any],
    x_name: str,
    y_name: str,
    *,
    title: str = "",
    caption: str = "",
    also: Sequence[str] = (),
) -> None:
    """Scatter plot of two features [m/s], colour = activity, marker = source group. Records of
    one activity and group at the same point are one mark of area proportional to their number,
    and larger marks are drawn behind smaller ones, so an activity whose records coincide with
    another's stays visible (:func:`scatter_marks`). ``also``: more formats, as :func:`save`'s."""
    from matplotlib.lines import Line2D

    markers = "o^sDvP*X"
    base = 14.0  # marker area of one record [pt^2]
    stacked = False
    with _rc_context():
        fig, ax = subplots(figsize=(6, 4.5), layout="constrained")
        handles = []
        for gi, group in enumerate(sorted(set(groups.tolist()))):
            for li, label in enumerate(sorted(set(labels.tolist()))):
                sel = (groups == group) & (labels == label)
                if not np.any(sel):
                    continue
                marker = markers[gi % len(markers)]
                xs, ys, counts = scatter_marks(x[sel], y[sel])
                stacked = stacked or bool(np.any(counts > 1))
                for n in np.unique(counts):
                    ax.scatter(
                        xs[counts == n],
                        ys[counts == n],
                        s=base * float(n),
                        marker=marker,
                        color=f"C{li}",
                        alpha=0.7,
                        zorder=2.0 + 1.0 / float(n),  # more records: further behind
                    )
                handles.append(
                    Line2D(
                        [],
                        [],
                        ls="",
                        marker=marker,
                        markersize=float(np.sqrt(base)),
                        color=f"C{li}",
                        alpha=0.7,
                        label=f"{label} ({group})",
                    )
                )
        ax.set_xlabel(f"{x_name} [m/s]")
        ax.set_ylabel(f"{y_name} [m/s]")
        ax.legend(handles=handles)
        if stacked:
            note = "marker area: number of records at the point"
            caption = f"{caption}; {note}" if caption else note
        save(fig, path, caption, title=title, also=also)


def plot_range_doppler(
    path: Path,
    power: NDArray[np.floating[Any]],
    range_m: NDArray[np.float64],
    velocity: NDArray[np.float64],
    *,
    title: str = "",
    caption: str = "",
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
    colormap: str = COLORMAP,
) -> None:
    """Save one range-Doppler map: ``power`` (n_doppler, n_range) linear [W], range [m] across,
    radial velocity [m/s] up (positive = approaching), in dB re the map's peak."""
    from .physics.spectrogram import power_to_db

    db = power_to_db(np.asarray(power, np.float64), -dynamic_range_db)
    with _rc_context():
        fig, ax = subplots(figsize=(7, 4), layout="constrained")
        im = _power_image(ax, db, range_m, velocity, dynamic_range_db, colormap)
        ax.set_xlabel("range [m]")
        ax.set_ylabel("radial velocity [m/s] (+ approaching)")
        fig.colorbar(im, ax=ax, label="power [dB re peak]")
        save(fig, path, caption, title=title)


def plot_point_cloud(
    path: Path,
    points: NDArray[np.float64],
    *,
    title: str = "",
    caption: str = "",
    v_limit: float | None = None,
) -> None:
    """Save a point cloud, ``points`` (n, 7) with columns frame, t, x, y, z, v, intensity: a top
    view (x across, y = boresight up) and a side view (y across, z up) in the sensor frame [m],
    coloured by radial velocity [m/s] (+ approaching; a diverging, colour-blind-safe map centred
    on zero), marker area by intensity."""
    x, y, z, v, snr = (points[:, k] for k in range(2, 7))
    lim = v_limit or max(float(np.max(np.abs(v))) if v.size else 1.0, 0.1)
    size = 6 + 2 * np.clip(snr, 0, 40) if snr.size else 6
    kw = dict(c=v, s=size, cmap="coolwarm", vmin=-lim, vmax=lim, edgecolors="none")
    with _rc_context():
        fig, (top, side) = subplots(1, 2, figsize=(9, 4.2), layout="constrained")
        top.scatter(x, y, **kw)
        sc = side.scatter(y, z, **kw)
        top.set_xlabel("x [m] (right)")
        top.set_ylabel("y [m] (boresight)")
        side.set_xlabel("y [m] (boresight)")
        side.set_ylabel("z [m] (up)")
        for ax in (top, side):
            ax.set_aspect("equal", adjustable="datalim")
            ax.grid(alpha=0.3)
        fig.colorbar(sc, ax=[top, side], label="radial velocity [m/s] (+ approaching)")
        if title:
            fig.suptitle(title)
        save(fig, path, caption)


def plot_spectrogram_panels(
    path: Path,
    panels: list[tuple[NDArray[np.floating[Any]], NDArray[np.float64], NDArray[np.float64], str]],
    *,
    dynamic_range_db: float = DYNAMIC_RANGE_DB,
    velocity_span: str | float = "auto",
    colormap: str = COLORMAP,
    caption: str = "",
) -> None:
    """Save spectrograms side by side, each panel ``(spectrogram_db (n_doppler, n_frames),
    time [s], velocity [m/s] (+ approaching), title)``, each in dB re its own peak on one colour
    scale (see :func:`draw_spectrogram`). The panels share one velocity axis: the union of
    their own limits, so no panel's power is cut off by another's span."""
    with _rc_context():
        fig, axes = subplots(
            1, len(panels), figsize=(5 * len(panels), 4), sharey=True, layout="constrained"
        )
        axes = np.atleast_1d(axes)
        im = None
        for k, (ax, (db, time, velocity, title)) in enumerate(zip(axes, panels, strict=True)):
            im = draw_spectrogram(
                ax,
                db,
                time,
                velocity,
                dynamic_range_db=dynamic_range_db,
                velocity_span=velocity_span,
                colormap=colormap,
            )
            ax.set_title(title)
            if k:
                ax.set_ylabel("")
        limits = [
            velocity_limits(db, velocity, velocity_span, dynamic_range_db)
            for db, _, velocity, _ in panels
        ]
        axes[0].set_ylim(min(lo for lo, _ in limits), max(hi for _, hi in limits))
        fig.colorbar(im, ax=list(axes), label="power [dB re peak]")
        save(fig, path, caption)


def run_caption(
    metadata: Mapping[str, Any],
    config: Mapping[str, Any],
    gate_range: tuple[float, float] | None = None,
) -> tuple[str, str]:
    """Title and caption of a run's figures, from its ``metadata.json`` and resolved config.

    The title names the activity and the source (file, subject); the caption gives the radar
    (kind, carrier, PRF or the slow-time rate of a radar without one), the geometry (aspect or
    heading, and ``gate_range``: the range gate [m] at the first and last pulse), the scatterer
    model and the effects that ran."""
    motion = dict(metadata.get("motion", {}))
    source = str(motion.get("source", config.get("motion", {}).get("kind", "?")))
    # an activity that only repeats the source's name (point targets) is said once
    activity = str(motion.get("activity") or "")
    what = [activity] if activity and activity != source else []
    origin = [source]
    if motion.get("file"):
        origin.append(str(motion["file"]))
    if motion.get("subject") is not None:
        origin.append(f"subject {motion['subject']}")
    title = " — ".join([*what, " ".join(origin)])

    radar = dict(config.get("radar", {}))
    f_c = float(metadata.get("carrier_frequency_hz", 0.0))
    prf = float(metadata.get("prf_hz", 0.0))
    # a pulsed radar's slow time is its PRF; a CW radar's is its I/Q rate, an FMCW radar's
    # its loop rate: neither has a ``prf`` field
    rate = "PRF" if "prf" in radar else "slow time"
    radar_part = f"{radar.get('kind', 'radar')} {f_c / 1e9:g} GHz, {rate} {prf:g} Hz"
    placement = dict(metadata.get("placement", {}))
    if placement.get("heading_deg") is not None:
        geometry = f"heading {placement['heading_deg']:g}°"
    elif "aspect_deg" in placement:
        geometry = f"aspect {placement.get('aspect_deg') or 0.0:g}°"
    else:
        geometry = "placed as given"
    if placement.get("motion") in ("treadmill", "straight"):
        geometry += f", {placement['motion']}"
    if gate_range is not None:
        geometry += f", range {gate_range[0]:.1f} → {gate_range[1]:.1f} m"
    effects = [str(e.get("kind")) for e in metadata.get("effects", [])]
    model = dict(config.get("scatterers", {})).get("kind", "?")
    parts = [
        radar_part,
        geometry,
        f"scatterers {model}",
        f"effects: {', '.join(effects) if effects else 'none'}",
    ]
    return title, "; ".join(parts)
