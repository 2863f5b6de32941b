"""``Result.plot()``: the common view of a command's result, drawn with Matplotlib.

One function per command (``_VIEWS``). Each draws into the Axes it is given (an Axes, or a sequence of Axes for a
view with several panels: as many panels are drawn as Axes are given, in the view's order) or into a new figure,
and returns what it drew into (an Axes, or a NumPy array of Axes). Axis labels carry the units of ``r.units``.
"""
from __future__ import annotations

import numpy as np

_PHASES = ("lag", "lead")


def _plt():
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("afmkit.Result.plot() needs matplotlib (Debian: apt install python3-matplotlib; or pip "
                          "install matplotlib)") from None
    return plt


def _axes(ax, panels: int, **subplots):
    """(list of Axes to draw into, value to return). ax None: a new figure with `panels` panels stacked."""
    if ax is None:
        fig, axes = _plt().subplots(panels, 1, squeeze=False, sharex=True, constrained_layout=True, **subplots)
        axes = list(axes[:, 0])
        return axes, (axes[0] if panels == 1 else np.array(axes, dtype=object))
    if hasattr(ax, "plot"):  # one Axes: the first panel
        return [ax], ax
    axes = list(np.ravel(np.asarray(ax, dtype=object)))
    if not axes or not all(hasattr(a, "plot") for a in axes):
        raise TypeError(f"ax must be a Matplotlib Axes or a sequence of Axes, not {type(ax).__name__}")
    if len(axes) > panels:
        raise ValueError(f"ax: {len(axes)} Axes given, this view has at most {panels} panels")
    return axes, np.array(axes, dtype=object)


def _label(r, column: str, name: str | None = None) -> str:
    return f"{name or column.replace('_', ' ')} [{r.units[column]}]"


def _phase(r, column: str, phase: str | None, native: str, degrees: bool):
    """The phase column in the convention asked for ("lag": the drive leads the response by φ; "lead": −φ) and its
    axis label."""
    phase = _convention(phase, native)
    unit = r.units[column]
    y = _phase_values(r[column], phase, native, degrees and unit == "rad")
    unit = "deg" if degrees and unit == "rad" else unit
    word = "phase lag" if phase == "lag" else "phase"
    return y, f"{word} [{unit}]"


def _convention(phase, native: str) -> str:
    if phase is None:
        return native
    if phase not in _PHASES:
        raise ValueError(f"phase = {phase!r} is not allowed: must be one of 'lag', 'lead' (None: as the command "
                         f"reports it, '{native}')")
    return phase


def _phase_values(values, phase, native: str, degrees: bool):
    """Phase values (rad, in the command's convention `native`) in the convention `phase`, in degrees if asked."""
    y = np.asarray(values, float) * (1.0 if _convention(phase, native) == native else -1.0)
    return np.degrees(y) if degrees else y


# ------------------------------------------------------------------------------------------ tapping sweep / fm
_DIRECTION_COLORS = {"approach": "#1f77b4", "retract": "#d62728", "down": "#1f77b4", "up": "#d62728",
                     "continuation": "#2ca02c"}


def _with_breaks(x, y, jumped):
    """x, y with a NaN inserted before every jumped row (the line is not drawn across a jump)."""
    cut = np.flatnonzero(jumped[1:]) + 1
    return np.insert(np.asarray(x, float), cut, np.nan), np.insert(np.asarray(y, float), cut, np.nan)


def _branch_panels(r, ax, panels, x: str, xlabel: str, folds=()):
    """Draw each panel (column values, y label, folds' values) along `x`, one line per direction in sweep order,
    broken and arrowed at jumps; unstable points as open circles; folds (separations) as diamonds."""
    axes, out = _axes(ax, len(panels))
    directions = list(dict.fromkeys(r["direction"])) if "direction" in r.keys() else ["approach"]
    for a, (y, ylabel, fold_y) in zip(axes, panels):
        for i, d in enumerate(directions):
            m = (r["direction"] == d) if "direction" in r.keys() else np.ones(len(r), bool)
            xs, ys, jumped, stable = r[x][m], y[m], r["jumped"][m], r["stable"][m]
            color = _DIRECTION_COLORS.get(d, f"C{i}")
            lx, ly = _with_breaks(xs, ys, jumped)
            a.plot(lx, ly, "-", color=color, lw=1.2, label=d)
            a.plot(xs[stable], ys[stable], ".", color=color, ms=4, label="_stable")
            if (~stable).any():
                a.plot(xs[~stable], ys[~stable], "o", mfc="none", mec=color, ms=5,
                       label="unstable" if i == 0 else "_unstable")
            for k in np.flatnonzero(jumped):
                if k > 0 and np.all(np.isfinite([xs[k - 1], ys[k - 1], xs[k], ys[k]])):
                    a.annotate("", xy=(xs[k], ys[k]), xytext=(xs[k - 1], ys[k - 1]),
                               arrowprops=dict(arrowstyle="->", color=color, lw=1.2, ls="--"))
        if np.any(r["jumped"]):
            a.plot([], [], "--", color="0.3", label="jump")
        if len(folds):
            a.plot(folds, fold_y, "D", mfc="none", mec="k", ms=6, label="fold")
        a.set_ylabel(ylabel)
        a.grid(alpha=0.3)
    axes[-1].set_xlabel(xlabel)
    axes[0].legend(fontsize=8)
    return out


def _sweep(r, ax=None, *, phase=None, degrees=False):
    """amplitude and phase against the swept parameter (separation, or --parameter: drive_frequency, ...), per
    direction (approach / retract or down / up, continuation)."""
    ph, ph_label = _phase(r, "phase", phase, "lag", degrees)
    x = r.results.get("parameter", "separation")
    folds = list(r.results.get("folds", []))  # mode continuation: folds of the parameter along the branches
    fl = np.array([f[x] for f in folds], float)
    fa = np.array([f["amplitude"] for f in folds], float)
    fp = _phase_values(np.array([f["phase"] for f in folds], float), phase, "lag", degrees)
    panels = [(np.asarray(r["amplitude"], float), _label(r, "amplitude"), fa), (ph, ph_label, fp)]
    return _branch_panels(r, ax, panels, x, _label(r, x), fl)


def _fm(r, ax=None, *, x="separation"):
    """frequency shift and drive (relative to the free cantilever's) against separation (or min_gap)."""
    if x not in ("separation", "min_gap"):
        raise ValueError(f"x = {x!r} is not allowed: must be 'separation' or 'min_gap'")
    panels = [(np.asarray(r["frequency_shift"], float), _label(r, "frequency_shift", "frequency shift Δf"), None),
              (np.asarray(r["drive_ratio"], float), _label(r, "drive_ratio", "drive / free drive"), None)]
    return _branch_panels(r, ax, panels, x, _label(r, x, "tip–sample gap" if x == "min_gap" else None))


# ------------------------------------------------------------------------------------------ tapping hb
_BRANCH_STYLE = {"free": ("-", "#1f77b4"), "plus": ("-", "#d62728"), "minus": (":", "#9467bd")}


def _segments(r, branch: str):
    """Index arrays of one branch, ordered in q and split where the branch has no root at a q sample of the curve
    (the minus root exists only on parts of the q range)."""
    q_all = np.unique(r["q"])
    idx = np.flatnonzero(r["branch"] == branch)
    idx = idx[np.argsort(r["q"][idx], kind="stable")]
    if len(idx) == 0:
        return []
    pos = np.searchsorted(q_all, r["q"][idx])
    return np.split(idx, np.flatnonzero(np.diff(pos) > 1) + 1)


def _hb(r, ax=None, *, phase=None, degrees=False):
    """amplitude and phase against separation, one line per branch (free, plus, minus root), folds marked."""
    ph, ph_label = _phase(r, "phase", phase, "lag", degrees)
    axes, out = _axes(ax, 2)
    folds = list(r.results.get("folds", []))
    for a, (y, ylabel, key) in zip(axes, [(np.asarray(r["amplitude"], float), _label(r, "amplitude"), "amplitude"),
                                          (ph, ph_label, "phase")]):
        for branch in dict.fromkeys(r["branch"]):
            ls, color = _BRANCH_STYLE.get(branch, ("-", "0.3"))
            for j, seg in enumerate(_segments(r, branch)):
                a.plot(r["separation"][seg], y[seg], ls, color=color, lw=1.3,
                       label=f"{branch} branch" if j == 0 else f"_{branch}")
        if folds:
            fy = np.array([f[key] for f in folds], float)
            if key == "phase":
                fy = _phase_values(fy, phase, "lag", degrees)
            a.plot([f["separation"] for f in folds], fy, "D", mfc="none", mec="k", ms=6, label="fold (dl/dq = 0)")
        a.set_ylabel(ylabel)
        a.grid(alpha=0.3)
    axes[-1].set_xlabel(_label(r, "separation"))
    axes[0].legend(fontsize=8)
    return out


# ------------------------------------------------------------------------------------------ control chart
def _chart(r, ax=None, *, delay=None, quantity=None, colorbar=True):
    """the chart on its grid (r.to_xarray()): the spectral abscissa (diverging colours about 0, its zero contour:
    the stability boundary) or the delay margin map; one panel per delay (delay=: one of them)."""
    from matplotlib.colors import TwoSlopeNorm

    ds = r.to_xarray()
    names = [v for v in ("spectral_abscissa", "critical_delay") if v in ds.data_vars]
    if quantity is None:
        quantity = names[0] if names else None
    if quantity not in ds.data_vars:
        raise ValueError(f"quantity = {quantity!r} is not allowed: must be one of "
                         f"{', '.join(str(v) for v in ds.data_vars)}")
    var = ds[quantity]
    if "delay" in var.dims:
        delays = [float(d) for d in ds["delay"].values]
        if delay is not None:
            near = [d for d in delays if np.isclose(d, delay, rtol=1e-9, atol=1e-12)]
            if not near:
                raise ValueError(f"delay = {delay!r} is not allowed: must be one of the chart's delays "
                                 f"({', '.join(f'{d:g}' for d in delays)} {r.units['delay']})")
            delays = near
        if ax is not None and hasattr(ax, "plot"):
            delays = delays[:1]
    else:
        delays = [None]
    if ax is None:
        fig, grid = _plt().subplots(1, len(delays), squeeze=False, figsize=(4.8 * len(delays), 4.0),
                                    constrained_layout=True)
        axes = list(grid[0])
        out = axes[0] if len(axes) == 1 else np.array(axes, dtype=object)
    else:
        axes, out = _axes(ax, len(delays))
    ydim, xdim = [d for d in var.dims if d != "delay"]
    xs, ys = ds[xdim].values, ds[ydim].values
    for a, d in zip(axes, delays):
        z = (var.sel(delay=d) if d is not None else var).transpose(ydim, xdim).values
        if quantity == "spectral_abscissa":
            finite = z[np.isfinite(z)]
            # each side of 0 its own full colour range (blue: stable, red: unstable), whatever the extremes
            scale = float(np.max(np.abs(finite))) if finite.size else 1.0
            tiny = 1e-9 * scale if scale > 0 else 1e-9
            low = min(float(finite.min()), -tiny) if finite.size else -1.0
            high = max(float(finite.max()), tiny) if finite.size else 1.0
            mesh = a.pcolormesh(xs, ys, np.ma.masked_invalid(z), cmap="RdBu_r", shading="nearest",
                                norm=TwoSlopeNorm(vmin=low, vcenter=0.0, vmax=high))
            if finite.size and finite.min() < 0 < finite.max() and len(xs) > 1 and len(ys) > 1:
                a.contour(xs, ys, np.ma.masked_invalid(z), levels=[0.0], colors="k", linewidths=1.2)
            title = "stable where < 0 (black: boundary)"
        else:
            mesh = a.pcolormesh(xs, ys, np.ma.masked_invalid(z), cmap="viridis", shading="nearest")
            title = ""
        if colorbar:
            a.figure.colorbar(mesh, ax=a, label=_label(r, quantity))
        head = f"delay = {d:g} {r.units['delay']}" if d is not None else quantity.replace("_", " ")
        a.set_title(f"{head}: {title}" if title else head, fontsize=9)
        a.set_xlabel(f"{xdim} [{ds[xdim].attrs.get('units', '')}]")
        a.set_ylabel(f"{ydim} [{ds[ydim].attrs.get('units', '')}]")
    return out


# ------------------------------------------------------------------------------------------ control tf
def _tf(r, ax=None, *, phase=None, degrees=True):
    """Bode plot: magnitude (log–log) and phase against frequency."""
    axes, out = _axes(ax, 2)
    f = np.asarray(r["frequency"], float)
    system = r.results.get("system", "response")
    axes[0].loglog(f, r["magnitude"], color="#1f77b4", lw=1.2, label=str(system))
    axes[0].set_ylabel(_label(r, "magnitude", f"|{system}|"))
    axes[0].grid(alpha=0.3, which="both")
    if len(axes) > 1:
        ph, ph_label = _phase(r, "phase", phase, "lead", degrees)
        axes[1].semilogx(f, ph, color="#1f77b4", lw=1.2)
        axes[1].set_ylabel(ph_label)
        axes[1].grid(alpha=0.3, which="both")
    axes[-1].set_xlabel(_label(r, "frequency"))
    return out


# ------------------------------------------------------------------------------------------ signals in time
def _signals(panels):
    def view(r, ax=None):
        """signals against time."""
        axes, out = _axes(ax, len(panels))
        for a, columns in zip(axes, panels):
            present = [c for c in columns if c in r.keys()]
            for c in present:
                a.plot(r["t"], r[c], lw=1.0, label=c)
            if present:
                units = {r.units[c] for c in present}
                a.set_ylabel(f"{', '.join(c.replace('_', ' ') for c in present)} [{', '.join(sorted(units))}]")
            if len(present) > 1:
                a.legend(fontsize=8)
            a.grid(alpha=0.3)
        axes[-1].set_xlabel(_label(r, "t", "time t"))
        return out
    return view


_simulate = _signals([("y", "target", "m"), ("u",)])
_impact = _signals([("gap",), ("force",)])


# ------------------------------------------------------------------------------------------ scan
_CHANNELS = ("topography", "deflection", "truth", "topography_lagged", "topography_inverse")


def _read_gsf(path):
    """A Gwyddion Simple Field file (docs/scan.md) as (array[YRes, XRes], header)."""
    raw = open(path, "rb").read()
    end = raw.index(b"\0")
    header = {}
    for line in raw[:end].decode("utf-8").splitlines()[1:]:
        if "=" in line:
            k, v = line.split("=", 1)
            header[k.strip()] = v.strip()
    nx, ny = int(header["XRes"]), int(header["YRes"])
    start = (end // 4 + 1) * 4
    return np.frombuffer(raw, "<f4", nx * ny, start).astype(float).reshape(ny, nx), header


def _scan(r, ax=None, *, channel="topography", colorbar=True):
    """one image of the scan (channel topography — the chosen reconstruction —, deflection, truth, or the other
    reconstruction topography_lagged / topography_inverse, from the GSF files it wrote); pixels outside the scanned
    disc blank."""
    if channel not in _CHANNELS:
        raise ValueError(f"channel = {channel!r} is not allowed: must be one of {', '.join(_CHANNELS)}")
    if channel == f"topography_{r.results.get('reconstruction')}":
        channel = "topography"  # the chosen reconstruction is written as <prefix>_topography
    files = [str(f) for f in r.results.get("files", [])]
    image = next((f for f in files if f.endswith(f"_{channel}.gsf")), None)
    mask = next((f for f in files if f.endswith(f"_{channel}_mask.gsf")), None)
    if image is None:
        raise NotImplementedError(
            "scan: this result holds no image (image_output was empty, or a recorded spiral without images); the "
            f"scan view draws an image channel ({', '.join(_CHANNELS)}) of a run with image_output=PREFIX; the "
            "per-turn table is r.radius, r.deflection_first_harmonic, ...")
    return _gsf_image(ax, image, mask, channel, "scan", colorbar)


def _gsf_image(ax, image: str, mask, channel: str, command: str, colorbar: bool):
    """Draws one GSF image a run wrote (pixels where `mask` < 0.5 blank) on its real extent, units from its header."""
    try:
        z, h = _read_gsf(image)
        m = _read_gsf(mask)[0] if mask is not None else None
    except OSError as e:
        raise FileNotFoundError(f"{command}: the image this run wrote cannot be read ({e.filename or image}: "
                                f"{e.strerror or e}); run the {command} again with image_output=PREFIX") from None
    if m is not None:
        z = np.where(m > 0.5, z, np.nan)
    x0, y0 = float(h.get("XOffset", 0)), float(h.get("YOffset", 0))
    xr, yr = float(h.get("XReal", z.shape[1])), float(h.get("YReal", z.shape[0]))
    axes, out = _axes(ax, 1)
    a = axes[0]
    im = a.imshow(z, extent=[x0, x0 + xr, y0 + yr, y0], interpolation="nearest", cmap="viridis")
    xy, zu = h.get("XYUnits", "m"), h.get("ZUnits", "m")
    if colorbar:
        a.figure.colorbar(im, ax=a, label=f"{channel} [{zu}]")
    a.set_xlabel(f"x [{xy}]")
    a.set_ylabel(f"y [{xy}]")
    a.set_title(h.get("Title", channel), fontsize=9)
    return out


# ------------------------------------------------------------------------------------------ tapping image
_IMAGE_CHANNELS = ("height", "error", "phase", "power", "peak_force", "regime", "truth")


def _image(r, ax=None, *, channel="height", direction="trace", colorbar=True):
    """one image of the virtual tapping-mode AFM (channel height — what the instrument shows —, error, phase, power,
    peak_force, regime, or the sample's truth; direction trace or retrace), from the GSF files it wrote."""
    if channel not in _IMAGE_CHANNELS:
        raise ValueError(f"channel = {channel!r} is not allowed: must be one of {', '.join(_IMAGE_CHANNELS)}")
    if direction not in ("trace", "retrace"):
        raise ValueError(f"direction = {direction!r} is not allowed: must be 'trace' or 'retrace'")
    suffix = "_truth.gsf" if channel == "truth" else f"_{channel}_{direction}.gsf"
    image = next((str(f) for f in r.results.get("files", []) if str(f).endswith(suffix)), None)
    if image is None:
        raise NotImplementedError(
            "tapping image: this result holds no image (image_output was empty); the view draws an image "
            f"({', '.join(_IMAGE_CHANNELS)}) of a run with image_output=PREFIX; the per-line metrics are "
            "r.regime_switches, r.max_peak_force, ...")
    return _gsf_image(ax, image, None, channel, "tapping image", colorbar)


# ------------------------------------------------------------------------------------------ tapping modes
def _modes(r, ax=None, *, phase=None, degrees=False):
    """amplitude and phase of each eigenmode against separation (the bimodal observable: mode 2's phase)."""
    axes, out = _axes(ax, 2)
    x = np.asarray(r["separation"], float)
    for k in (1, 2, 3):
        amplitude = np.asarray(r[f"amplitude_{k}"], float)
        if not np.isfinite(amplitude).any():
            continue  # a mode the run did not have
        panels = [(amplitude, _label(r, f"amplitude_{k}", "amplitude")),
                  _phase(r, f"phase_{k}", phase, "lag", degrees)]
        for a, (y, ylabel) in zip(axes, panels):
            a.plot(x, y, ".-", lw=1.2, ms=3, label=f"mode {k}")
            a.set_ylabel(ylabel)
    for a in axes:
        a.grid(alpha=0.3)
    axes[-1].set_xlabel(_label(r, "separation"))
    axes[0].legend(fontsize=8)
    return out


_VIEWS = {"tapping sweep": _sweep, "tapping fm": _fm, "tapping hb": _hb, "control chart": _chart,
          "control tf": _tf, "control simulate": _simulate, "impact": _impact, "scan": _scan,
          "tapping image": _image, "tapping modes": _modes}


def plot(r, ax=None, **kwargs):
    view = _VIEWS.get(r.command)
    if view is None:
        raise NotImplementedError(f"{r.command}: no plot view; Result.plot() draws the results of "
                                  f"{', '.join(_VIEWS)} (other results: r.to_pandas().plot(...) or Matplotlib on the "
                                  f"columns)")
    import inspect
    allowed = [k for k, p in inspect.signature(view).parameters.items() if p.kind is p.KEYWORD_ONLY]
    unknown = [k for k in kwargs if k not in allowed]
    if unknown:
        raise TypeError(f"{r.command}: plot() got the keyword {unknown[0]!r}, which this view does not take "
                        f"(keywords: {', '.join(['ax'] + allowed)})")
    if len(r) == 0 and r.command not in ("scan", "tapping image"):
        raise ValueError(f"{r.command}: the result has no rows: nothing to plot")
    return view(r, ax, **kwargs)
