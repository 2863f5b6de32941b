"""Figures of the virtual rotational-scanning AFM (``afmkit scan``, docs/scan.md): a tilted sample imaged without
and with the seed-2 controller, and the scan-area gain the controller buys.

The images are the GSF files the command writes (Gwyddion Simple Field: a text header, NUL padding to a multiple of
4 bytes, then XRes × YRes little-endian float32 heights in metres, with a ``_mask.gsf`` beside each: 1 valid, 0
invalid); they are written into a temporary folder and read back here.
"""
from __future__ import annotations

import math
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import afmkit  # noqa: E402
from afmkit.figures import figure, finish  # noqa: E402

#: the scan of the report (keywords of afmkit.scan; docs/scan.md)
SCAN = dict(sample="grating", sample_resolution=512, tilt_angle=0.05, end_radius=4e-3, radial_speed=400e-6,
            sample_rate=50e3, spindle_frequency=50.0, delay=1e-3, detector_range=2e-6, harmonics=10, alpha=0.1,
            beta=-0.1, image_resolution=192)


def read_gsf(path) -> tuple[np.ndarray, dict]:
    """A Gwyddion Simple Field file as (array[YRes, XRes] of float64, header dict)."""
    raw = pathlib.Path(path).read_bytes()
    end = raw.index(b"\0")
    lines = raw[:end].decode("utf-8").splitlines()
    if not lines or lines[0].strip() != "Gwyddion Simple Field 1.0":
        raise ValueError(f"{path}: not a Gwyddion Simple Field 1.0 file")
    header = {}
    for ln in lines[1:]:
        if "=" in ln:
            k, v = ln.split("=", 1)
            header[k.strip()] = v.strip()
    nx, ny = int(header["XRes"]), int(header["YRes"])
    start = (end // 4 + 1) * 4  # 1..4 NUL bytes pad the header to a multiple of 4
    data = np.frombuffer(raw, dtype="<f4", count=nx * ny, offset=start).astype(float)
    return data.reshape(ny, nx), header


def read_image(prefix: str, channel: str) -> tuple[np.ndarray, dict]:
    """Channel image of a scan with invalid pixels as NaN (from the ``_mask.gsf`` beside it)."""
    z, h = read_gsf(f"{prefix}_{channel}.gsf")
    mask, _ = read_gsf(f"{prefix}_{channel}_mask.gsf")
    return np.where(mask > 0.5, z, np.nan), h


def _level(z: np.ndarray) -> np.ndarray:
    """Subtract the least-squares plane of the valid pixels (for display of the features)."""
    ny, nx = z.shape
    yy, xx = np.mgrid[0:ny, 0:nx]
    ok = np.isfinite(z)
    A = np.c_[np.ones(ok.sum()), xx[ok], yy[ok]]
    c, *_ = np.linalg.lstsq(A, z[ok], rcond=None)
    return z - (c[0] + c[1] * xx + c[2] * yy)


@figure("beyond-scan-images")
def scan_images(out=None, *, sample: str = SCAN["sample"], sample_resolution: int = SCAN["sample_resolution"],
                tilt_angle: float = SCAN["tilt_angle"], end_radius: float = SCAN["end_radius"],
                radial_speed: float = SCAN["radial_speed"], sample_rate: float = SCAN["sample_rate"],
                spindle_frequency: float = SCAN["spindle_frequency"], delay: float = SCAN["delay"],
                detector_range: float = SCAN["detector_range"], harmonics: int = SCAN["harmonics"],
                alpha: float = SCAN["alpha"], beta: float = SCAN["beta"],
                image_resolution: int = SCAN["image_resolution"]):
    """Beyond the papers: the virtual rotational scan (``afmkit.scan``) of a tilted sample without and with the
    controller: deflection images, reconstructed topography, residual tilt against radius, scan-area gain.

    The keywords are those of ``afmkit.scan`` (SI units, docs/scan.md; checked there, ValueError naming the key):
    tilt_angle (degrees), end_radius (m), radial_speed (m/s), sample_rate and spindle_frequency (Hz), delay (s),
    detector_range (m), harmonics, alpha and beta (Ω), sample_resolution and image_resolution (pixels); the
    defaults are :data:`SCAN`. Returns the Matplotlib Figure (``fig.report``: caption, key numbers); writes the
    PNG if ``out``."""
    params = dict(sample=sample, sample_resolution=sample_resolution, tilt_angle=tilt_angle, end_radius=end_radius,
                  radial_speed=radial_speed, sample_rate=sample_rate, spindle_frequency=spindle_frequency,
                  delay=delay, detector_range=detector_range, harmonics=harmonics, alpha=alpha, beta=beta,
                  image_resolution=image_resolution)
    with tempfile.TemporaryDirectory(prefix="afmkit-scan-") as tmp:
        off_prefix, on_prefix = f"{tmp}/off", f"{tmp}/on"
        r_off = afmkit.scan(control="off", image_output=off_prefix, **params)
        r_on = afmkit.scan(control="on", image_output=on_prefix, **params)
        d_off, hdr = read_image(off_prefix, "deflection")
        d_on, _ = read_image(on_prefix, "deflection")
        topo_on, _ = read_image(on_prefix, "topography")
        truth, _ = read_image(on_prefix, "truth")
    res = r_on.results
    half = float(hdr.get("XReal", 2 * params["end_radius"])) / 2 * 1e3  # mm
    ext = [-half, half, half, -half]  # row 0 at the top (y down, Gwyddion's convention)

    fig, axes = plt.subplots(2, 3, figsize=(12.7, 8.2), constrained_layout=True)
    kw = dict(extent=ext, interpolation="nearest")
    cmap = plt.get_cmap("viridis").copy()
    cmap.set_bad("0.85")
    a = axes[0, 0]
    im = a.imshow(d_off * 1e6, cmap=cmap, **kw)
    fig.colorbar(im, ax=a, label="deflection d [µm]", shrink=0.85)
    a.set_title("controller off: deflection\n(tilt dominates; grey: saturated)", fontsize=10)
    a = axes[0, 1]
    im = a.imshow(d_on * 1e9, cmap=cmap, **kw)
    fig.colorbar(im, ax=a, label="deflection d [nm]", shrink=0.85)
    a.set_title("controller on: deflection\n(tilt removed, grating kept)", fontsize=10)
    a = axes[0, 2]
    im = a.imshow(_level(topo_on) * 1e9, cmap=cmap, **kw)
    fig.colorbar(im, ax=a, label="height (plane-levelled) [nm]", shrink=0.85)
    a.set_title("controller on: reconstruction\n(plant's lag removed; plane-levelled)", fontsize=10)
    for a in axes[0]:
        a.set_xlabel("x [mm]")
        a.set_ylabel("y [mm]")
    # per-turn residual first harmonic against radius
    a = axes[1, 0]
    a.semilogy(r_off["radius"] * 1e3, r_off["deflection_first_harmonic"] * 1e9, color="tab:red", lw=1,
               label="controller off: deflection")
    a.semilogy(r_on["radius"] * 1e3, r_on["deflection_first_harmonic"] * 1e9, color="tab:blue", lw=1,
               label="controller on: deflection")
    a.semilogy(r_on["radius"] * 1e3, r_on["tilt_first_harmonic"] * 1e9, color="0.5", lw=1, ls="--",
               label="tilt r·tan ψ")
    a.axhline(params["detector_range"] * 1e9, color="k", ls=":", lw=1, label="detector range")
    a.set_xlabel("radius r [mm]")
    a.set_ylabel("first harmonic per turn [nm]")
    a.set_title("residual first harmonic of each turn")
    a.legend(fontsize=8)
    # profile along the central row
    a = axes[1, 1]
    row = d_on.shape[0] // 2
    x = np.linspace(-half, half, d_on.shape[1])
    a.plot(x, _level(truth)[row] * 1e9, color="0.5", lw=2, label="ground truth (levelled)")
    a.plot(x, _level(topo_on)[row] * 1e9, color="tab:green", lw=1, label="reconstruction (levelled)")
    a.plot(x, d_on[row] * 1e9, color="tab:blue", lw=0.8, label="deflection, controller on")
    a.set_xlabel("x [mm] (central row)")
    a.set_ylabel("height [nm]")
    a.set_title("profile through the centre")
    a.legend(fontsize=8)
    # scan area
    a = axes[1, 2]
    r_no = res["max_radius_without_control"]
    r_yes = res["max_radius_with_control"]
    for rad, col, lab in ((r_yes, "tab:blue", "controller on"), (r_no, "tab:red", "controller off")):
        a.add_patch(plt.Circle((0, 0), rad * 1e3, color=col, alpha=0.35, label=f"{lab}: r = {rad * 1e3:.2f} mm"))
    a.set_xlim(-half, half)
    a.set_ylim(-half, half)
    a.set_aspect("equal")
    gain = res["scan_area_gain"]
    lb = "≥ " if res["scan_area_gain_is_lower_bound"] else ""
    a.set_title(f"area before saturation: gain {lb}{gain:.2f}", fontsize=10)
    a.set_xlabel("x [mm]")
    a.set_ylabel("y [mm]")
    a.legend(fontsize=8, loc="lower right")
    def g(v, d=3):
        return f"{v:.{d}g}" if isinstance(v, (int, float)) and math.isfinite(v) else str(v)

    numbers = [("scan-area gain (r_on² − r₀²)/(r_off² − r₀²)", f"{lb}{g(gain, 4)}",
                "afmkit scan: scan_area_gain" + (" (lower bound: never saturated with control)" if lb else "")),
               ("largest radius before saturation, controller off", f"{g(r_no * 1e3, 4)} mm",
                "afmkit scan: max_radius_without_control (docs/scan.md: ≈ 2.3 mm)"),
               ("largest radius before saturation, controller on", f"{g(r_yes * 1e3, 4)} mm",
                "afmkit scan: max_radius_with_control"),
               ("saturated fraction of samples, controller on / off",
                f"{g(res['saturated_fraction'])} / {g(r_off.results['saturated_fraction'])}", "afmkit scan"),
               ("topography RMS error (levelled), inverse / lagged reconstruction",
                f"{g(res['inverse_rms_error'] * 1e9)} / {g(res['lagged_rms_error'] * 1e9)} nm",
                "afmkit scan: inverse_rms_error, lagged_rms_error (docs/scan.md#reconstruction)"),
               ("residual first harmonic of the last turn, controller on",
                f"{g(float(r_on['deflection_first_harmonic'][-1]) * 1e9)} nm", "afmkit scan: per-turn table"),
               ("loop spectral abscissa at the nominal delay", f"{g(res['loop_spectral_abscissa'], 4)} 1/s",
                "afmkit scan: loop_spectral_abscissa")]
    return finish(
        fig, out, "beyond-scan-images",
        title="Beyond the paper: virtual rotational scan of a tilted grating without and with the controller",
        caption=(f"A {sample} ({'period 800 µm, lines 50 nm, ' if sample == 'grating' else ''}"
                 f"{sample_resolution}² sample map) tilted by {tilt_angle:g}° spins at {spindle_frequency:g} Hz under a "
                 f"tip moving outwards at {radial_speed * 1e6:g} µm/s to r = {end_radius * 1e3:g} mm "
                 f"({sample_rate / 1e3:g} kHz sampling, plant rate γ = 2π·1 kHz, actuator delay {delay * 1e3:g} ms "
                 f"= {delay * spindle_frequency:g} T, detector range ±{detector_range * 1e6:g} µm); controller: bank "
                 f"of N = {harmonics} oscillators, α = {alpha:g}Ω, β = {beta:g}Ω, ".replace("-", "−") +
                 "K = γ. Without control the tilt's first harmonic grows as r·tan ψ and saturates the detector at "
                 f"r = {r_no * 1e3:.2f} mm; with control the deflection keeps only the grating lines and the whole "
                 f"disc is imaged (scan-area gain {lb}{gain:.2f}). The controller also removes the grating's own "
                 "first harmonic on each circle (the rings in the controlled deflection); the reconstruction "
                 "(deflection + actuator with the plant's first-order lag removed, seed 2 eq. 1) restores it and "
                 "matches the truth after levelling up to the imaging's interpolation between samples; without the "
                 "inversion (d + z_a) the image is turned by the lag atan(Ω/γ) ≈ 2.9°. Without control the valid area is the band |x| < r_off "
                 f"(tilt along x). Images {image_resolution} × {image_resolution} pixels, read back from the GSF "
                 "files afmkit writes."),
        numbers=numbers)


FIGURES = [scan_images]
