"""Result.plot() (docs/python.md#plots): each view draws the result's own columns (read back from the Matplotlib
artists and compared with the table), into the Axes it is given; commands without a view raise
NotImplementedError. Small runs, Agg backend: about a second in all."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import QuadMesh  # noqa: E402

import afmkit  # noqa: E402

# the repulsive-attractive case of the demo (bistable at omega = 0.99 omega_n: jumps, an unstable branch, folds)
ATTRACTIVE = dict(law="attractive", approach_adhesion=0.5, departure_adhesion=1.0, frequency_ratio=0.99)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def instrument():
    return afmkit.tapping.sweep(**ATTRACTIVE, separation_min=8, separation_max=11, points=13, mode="instrument",
                                quiet=True)


@pytest.fixture(scope="module")
def continuation():
    return afmkit.tapping.sweep(**ATTRACTIVE, separation_min=8, separation_max=11, points=13, mode="continuation",
                                quiet=True)


@pytest.fixture(scope="module")
def hb():
    return afmkit.tapping.hb(**ATTRACTIVE, points=200)


def _line(ax, label):
    lines = [ln for ln in ax.get_lines() if ln.get_label() == label]
    assert len(lines) == 1, f"{label}: {[ln.get_label() for ln in ax.get_lines()]}"
    return np.asarray(lines[0].get_xdata(), float), np.asarray(lines[0].get_ydata(), float)


def _finite(x):
    return x[np.isfinite(x)]


def test_sweep_draws_each_direction_broken_and_arrowed_at_its_jumps(instrument):
    r = instrument
    assert r.jumped.any(), "the case must jump (else the test shows nothing)"
    axes = r.plot()
    assert len(axes) == 2
    for d in ("approach", "retract"):
        m = r.direction == d
        x, y = _line(axes[0], d)
        np.testing.assert_array_equal(_finite(x), r.separation[m])
        np.testing.assert_array_equal(_finite(y), r.amplitude[m])
        # one break (NaN) per jumped row of that direction, none elsewhere
        assert np.isnan(x).sum() == r.jumped[m][1:].sum()
        _, p = _line(axes[1], d)
        np.testing.assert_array_equal(_finite(p), r.phase[m])  # default: as reported (a lag)
    arrows = [t for t in axes[0].texts if getattr(t, "arrow_patch", None) is not None]
    assert len(arrows) == sum(r.jumped[r.direction == d][1:].sum() for d in ("approach", "retract"))
    assert axes[0].get_ylabel() == f"amplitude [{r.units['amplitude']}]"
    assert axes[1].get_xlabel() == f"separation [{r.units['separation']}]"


def test_sweep_marks_unstable_points_and_folds_and_the_phase_convention_is_selectable(continuation):
    r = continuation
    assert (~r.stable).any() and len(r.results.folds) >= 1
    axes = r.plot(phase="lead", degrees=True)
    x, y = _line(axes[0], "unstable")
    np.testing.assert_array_equal(x, r.separation[~r.stable])
    np.testing.assert_array_equal(y, r.amplitude[~r.stable])
    _, p = _line(axes[1], "continuation")
    np.testing.assert_allclose(_finite(p), -r.phase * 180 / np.pi, rtol=1e-15)
    assert axes[1].get_ylabel() == "phase [deg]"
    fx, fy = _line(axes[0], "fold")
    np.testing.assert_array_equal(fx, [f["separation"] for f in r.results.folds])
    np.testing.assert_array_equal(fy, [f["amplitude"] for f in r.results.folds])
    with pytest.raises(ValueError, match="phase = 'behind' is not allowed.*'lag', 'lead'"):
        r.plot(phase="behind")


def test_hb_draws_every_branch_and_its_folds(hb):
    r = hb
    axes = r.plot()
    for branch in set(r.branch):
        m = r.branch == branch
        pts = set()
        for ln in axes[0].get_lines():
            if ln.get_label() in (f"{branch} branch", f"_{branch}"):
                pts |= set(zip(ln.get_xdata(), ln.get_ydata()))
        assert pts == set(zip(r.separation[m], r.amplitude[m])), branch
    fx, fy = _line(axes[0], "fold (dl/dq = 0)")
    np.testing.assert_array_equal(fx, [f["separation"] for f in r.results.folds])
    np.testing.assert_array_equal(fy, [f["amplitude"] for f in r.results.folds])
    _, fp = _line(axes[1], "fold (dl/dq = 0)")
    np.testing.assert_array_equal(fp, [f["phase"] for f in r.results.folds])


def test_chart_draws_one_panel_per_delay_on_the_grid():
    r = afmkit.control.chart(harmonics=2, x_points=5, y_points=4, delays=[0.3, 0.1], boundaries_output="",
                             progress=False)
    axes = r.plot()
    assert len(axes) == 2
    xs, ys = np.unique(r.x), np.unique(r.y)
    for a, d in zip(axes, sorted(set(r.delay))):
        # the long table re-gridded by hand (independent of to_xarray)
        z = np.full((len(ys), len(xs)), np.nan)
        m = r.delay == d
        z[np.searchsorted(ys, r.y[m]), np.searchsorted(xs, r.x[m])] = r.spectral_abscissa[m]
        mesh = [c for c in a.collections if isinstance(c, QuadMesh)]
        assert len(mesh) == 1
        np.testing.assert_array_equal(np.ma.filled(mesh[0].get_array(), np.nan).ravel(), z.ravel())
        assert f"{d:g}" in a.get_title()
        assert a.get_xlabel() == f"{r.results.x} [Omega]"
    fig, ax = plt.subplots()
    assert r.plot(ax=ax, delay=0.3) is ax
    with pytest.raises(ValueError, match="delay = 0.5 is not allowed: must be one of the chart's delays"):
        r.plot(delay=0.5)


def test_tf_is_a_bode_plot():
    r = afmkit.control.tf(points=30, system="loop")
    axes = r.plot()
    (mag,), (ph,) = axes[0].get_lines(), axes[1].get_lines()
    np.testing.assert_array_equal(mag.get_xdata(), r.frequency)
    np.testing.assert_array_equal(mag.get_ydata(), r.magnitude)
    np.testing.assert_allclose(ph.get_ydata(), np.degrees(r.phase), rtol=1e-15)
    assert axes[0].get_xscale() == "log" and axes[0].get_yscale() == "log"
    assert axes[1].get_xlabel() == "frequency [Omega]"
    (ph,) = r.plot(phase="lag", degrees=False)[1].get_lines()
    np.testing.assert_array_equal(ph.get_ydata(), -r.phase)


@pytest.mark.parametrize("command, panels", [
    ("control simulate", [("y", "target", "m"), ("u",)]),
    ("impact", [("gap",), ("force",)]),
])
def test_signals_against_time(command, panels):
    r = (afmkit.control.simulate(periods=3, steps_per_period=100) if command == "control simulate"
         else afmkit.impact(points=50))
    axes = r.plot()
    for a, columns in zip(axes, panels):
        lines = a.get_lines()
        assert [ln.get_label() for ln in lines] == list(columns)
        for ln, c in zip(lines, columns):
            np.testing.assert_array_equal(ln.get_xdata(), r.t)
            np.testing.assert_array_equal(ln.get_ydata(), r[c])
        assert r.units[columns[0]] in a.get_ylabel()
    assert axes[-1].get_xlabel() == f"time t [{r.units['t']}]"


def test_scan_draws_its_image_and_says_what_it_needs_without_one(tmp_path):
    r = afmkit.scan(sample_resolution=64, end_radius=5e-4, radial_speed=1e-3, sample_rate=5000, image_resolution=16,
                    image_output=str(tmp_path / "s"), output="")
    ax = r.plot(channel="truth")
    (im,) = ax.get_images()
    z = im.get_array()
    assert z.shape == (16, 16)
    assert np.isfinite(np.ma.filled(z, np.nan)).sum() == r.results.valid_pixels
    # the extent is the disc scanned: 2 end_radius across, centred
    np.testing.assert_allclose(im.get_extent(), [-5e-4, 5e-4, 5e-4, -5e-4], rtol=1e-6)
    none = afmkit.scan(sample_resolution=64, end_radius=5e-4, radial_speed=1e-3, sample_rate=5000,
                       image_resolution=16, image_output="", output="")
    with pytest.raises(NotImplementedError, match="holds no image.*topography, deflection, truth"):
        none.plot()
    (tmp_path / "s_deflection.gsf").unlink()
    with pytest.raises(FileNotFoundError, match="scan: the image this run wrote cannot be read.*s_deflection.gsf"):
        r.plot(channel="deflection")


def test_draws_into_the_axes_given(instrument):
    fig, ax = plt.subplots()
    assert instrument.plot(ax=ax) is ax
    assert len(fig.axes) == 1  # no new figure, no second panel
    x, _ = _line(ax, "approach")
    np.testing.assert_array_equal(_finite(x), instrument.separation[instrument.direction == "approach"])
    fig, two = plt.subplots(1, 2)
    out = instrument.plot(ax=two)
    assert list(out) == list(two)
    assert two[1].get_ylabel().startswith("phase lag")
    with pytest.raises(ValueError, match="3 Axes given, this view has at most 2 panels"):
        instrument.plot(ax=plt.subplots(3)[1])


def test_a_command_without_a_view_says_which_have_one():
    r = afmkit.control.margin()
    with pytest.raises(NotImplementedError, match="control margin: no plot view.*tapping sweep.*control chart"):
        r.plot()


def test_a_keyword_the_view_does_not_take_is_named_with_the_allowed_ones(instrument):
    with pytest.raises(TypeError, match="tapping sweep: plot\\(\\) got the keyword 'channel'.*keywords: ax, phase, "
                                        "degrees"):
        instrument.plot(channel="truth")


def test_an_empty_result_is_refused_not_drawn_blank(instrument):
    raw = {"table": {c: instrument[c][:0] for c in instrument.columns}, "results": {}, "params": {},
           "columns": [(c, instrument.units[c], instrument.meaning[c]) for c in instrument.columns]}
    empty = afmkit.Result("tapping sweep", raw)
    with pytest.raises(ValueError, match="tapping sweep: the result has no rows: nothing to plot"):
        empty.plot()


def _gsf_by_hand(path):
    """A GSF file read here, independently of the module: header up to NUL, padding to 4 bytes, float32 LE."""
    raw = open(path, "rb").read()
    end = raw.index(b"\0")
    head = dict(line.split(" = ", 1) for line in raw[:end].decode().splitlines()[1:] if " = " in line)
    nx, ny = int(head["XRes"]), int(head["YRes"])
    start = end + (4 - end % 4)
    return np.frombuffer(raw[start:start + 4 * nx * ny], "<f4").reshape(ny, nx), head


def test_tapping_image_draws_the_channel_and_direction_asked_for(tmp_path):
    r = afmkit.tapping.image(sample="steps", pixels=12, lines=4, map_points=40, image_output=str(tmp_path / "i"),
                             output="", quiet=True)
    for channel, direction in [("height", "trace"), ("peak_force", "retrace"), ("truth", "trace")]:
        ax = r.plot(channel=channel, direction=direction)
        (im,) = ax.get_images()
        name = "i_truth.gsf" if channel == "truth" else f"i_{channel}_{direction}.gsf"
        z, head = _gsf_by_hand(tmp_path / name)
        np.testing.assert_array_equal(np.ma.filled(im.get_array(), np.nan), z.astype(float))
        assert ax.figure.axes[-1].get_ylabel() == f"{channel} [{head['ZUnits']}]"  # the colour bar
        width = float(head["XReal"])
        np.testing.assert_allclose(abs(im.get_extent()[1] - im.get_extent()[0]), width, rtol=1e-12)
        plt.close("all")
    with pytest.raises(ValueError, match="channel = 'topography' is not allowed: must be one of height"):
        r.plot(channel="topography")
    none = afmkit.tapping.image(pixels=4, lines=2, map_points=20, image_output="", output="", quiet=True)
    with pytest.raises(NotImplementedError, match="tapping image: this result holds no image"):
        none.plot()


def test_tapping_modes_draws_each_mode_it_has():
    r = afmkit.tapping.modes(modes=2, points=4, settle_periods=40, lockin_periods=4, output="", quiet=True)
    amplitude, phase = r.plot(degrees=True)
    for k in (1, 2):
        x, y = _line(amplitude, f"mode {k}")
        np.testing.assert_array_equal(x, r.separation)
        np.testing.assert_array_equal(y, r[f"amplitude_{k}"])
        np.testing.assert_allclose(_line(phase, f"mode {k}")[1], np.degrees(r[f"phase_{k}"]), rtol=1e-15)
    assert [ln.get_label() for ln in amplitude.get_lines()] == ["mode 1", "mode 2"]  # no third mode drawn
    assert phase.get_ylabel() == "phase lag [deg]"
