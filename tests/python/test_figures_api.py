"""The figure functions as a Python interface (afmkit.figures.seed000, seed003, scan): keyword parameters that the
drawn data follow, a Matplotlib Figure returned, a PNG written only when asked, bad keywords refused by name.
Light: small grids and short runs, no figure of the report at its full size."""
import inspect
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from afmkit.figures import ReportEntry, scan, seed000, seed003  # noqa: E402

FUNCTIONS = seed000.FIGURES + seed003.FIGURES + scan.FIGURES


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _labelled_lines(ax):
    return [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]


def test_every_figure_function_takes_keywords_with_defaults():
    for fn in FUNCTIONS:
        params = list(inspect.signature(fn).parameters.values())
        assert params[0].name == "out" and params[0].default is None, fn.__name__
        rest = params[1:]
        assert rest, f"{fn.__name__} has no parameters besides out"
        for p in rest:
            assert p.kind is p.KEYWORD_ONLY and p.default is not p.empty, (fn.__name__, p.name)
        assert "Returns the Matplotlib Figure" in " ".join((fn.__doc__ or "").split()), fn.__name__


def test_fig3_with_other_parameters_draws_them_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    free = 10.0  # nm, half the report's
    fig = seed000.fig3(free_amplitude=free, stiffness_ratios=[1.0, 100.0], q_range=(0.5, 1.05), points=120,
                       probe_separation=5.0)
    assert isinstance(fig, Figure)
    assert os.listdir(tmp_path) == []  # out=None: no file
    ax = fig.axes[0]
    curves = _labelled_lines(ax)
    assert [c.get_label() for c in curves] == ["K_a/ω_n² = 1", "K_a/ω_n² = 100"]
    for c in curves:
        q, l = c.get_xdata(), c.get_ydata()
        assert q.min() == pytest.approx(0.5, abs=0.01) and q.max() == pytest.approx(1.05, abs=0.01)
        # no contact beyond q = 1: l = q A_free with the free amplitude asked for (seed-1, after eq. 19)
        np.testing.assert_allclose(l[q > 1.0], q[q > 1.0] * free, rtol=1e-6)
    assert ax.get_xlim() == pytest.approx((0.5, 1.05))
    assert ax.get_ylim() == pytest.approx((-0.25 * free, 1.5 * free))
    entry = fig.report
    assert isinstance(entry, ReportEntry) and entry.id == "seed000-fig3" and entry.filename == ""
    assert "free amplitude 10 nm" in entry.caption and "K_a/ω_n² = 1, 100" in entry.caption
    assert len(entry.numbers) == 2 and all("l = 5 nm" in row[0] for row in entry.numbers)
    marked = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]  # the solutions at l = 5 nm
    assert len(marked) == 2 and all(ln.get_ydata()[0] == pytest.approx(5.0, rel=1e-6) for ln in marked)


def test_numpy_arrays_and_scalars_are_accepted():
    fig = seed000.fig4(stiffness_ratios=np.array([1, 10]), free_amplitude=np.float32(15.0), points=np.int64(80))
    labels = [ln.get_label() for ln in _labelled_lines(fig.axes[0])]
    assert labels[:2] == ["K_a/ω_n² = 1", "K_a/ω_n² = 10"]
    assert fig.axes[0].get_ylim() == pytest.approx((0.0, 22.5))  # 1.5 A_free


def test_out_writes_the_png_into_a_folder_or_to_a_file_name(tmp_path):
    fig = seed000.fig3(tmp_path / "a", stiffness_ratios=[10.0], points=60)
    assert sorted(os.listdir(tmp_path / "a")) == ["seed000-fig3.png"]
    assert fig.report.filename == "seed000-fig3.png"
    fig = seed000.fig3(str(tmp_path / "mine.png"), stiffness_ratios=[10.0], points=60)
    assert (tmp_path / "mine.png").stat().st_size > 1000 and fig.report.filename == "mine.png"


def test_a_seed003_time_series_follows_its_run_parameters():
    fig = seed003.fig3(delays=[0.05], periods=6, steps_per_period=50, zoom_periods=2.0)
    zoom, whole, per_period = fig.axes[:3]
    y = [ln for ln in _labelled_lines(zoom) if ln.get_label().startswith("τ")]
    assert len(y) == 1 and y[0].get_xdata().max() <= 2.0 + 1e-9
    t = _labelled_lines(whole)[0].get_xdata()
    assert 6.0 - 0.05 <= t.max() <= 6.0 and np.all(np.diff(t) > 0)  # the 6 periods, sampled every 1/50
    assert "AB3 with 50 steps per period, 6 periods" in fig.report.caption


@pytest.mark.parametrize("fn, keywords, name", [
    (seed000.fig3, dict(points=0), "points"),
    (seed000.fig3, dict(q_range=(1.1, 0.2)), "q_range"),
    (seed000.fig3, dict(stiffness_ratios=[]), "stiffness_ratios"),
    (seed000.fig4, dict(free_amplitude=-1.0), "free_amplitude"),
    (seed000.fig_attractive, dict(sweep_ratio=0.5), "sweep_ratio"),
    (seed000.fig_hb_vs_orbits, dict(cases=[]), "cases"),
    (seed000.fig_impact, dict(bodies=[dict(mass1=1.0)]), "bodies"),
    (seed003.fig2, dict(a_points=1), "a_points"),
    (seed003.fig3, dict(gain=0.0), "gain"),
    (seed003.fig4, dict(delays=[-0.1]), "delays[0]"),
    (seed003.fig5, dict(harmonics=0), "harmonics"),
    (seed003.fig7, dict(plant_rate=float("nan")), "plant_rate"),
    (seed003.spotchecks, dict(offset=1.5), "offset"),
    (seed003.tuning, dict(gain_ratio_range=(2.0, 0.5)), "gain_ratio_range"),
    (scan.scan_images, dict(image_resolution=0), "image_resolution"),
    (seed000.fig3, dict(out=3), "out"),
])
def test_a_bad_keyword_raises_a_value_error_naming_it(fn, keywords, name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError, match=rf"\b{name.replace('[', '.').replace(']', '.')}"):
        fn(**keywords)
    assert os.listdir(tmp_path) == []


def test_an_unknown_keyword_is_refused():
    with pytest.raises(TypeError, match="frequency"):
        seed000.fig3(frequency=300.0)


def test_save_png_draws_once_and_writes_the_pixels_savefig_writes(tmp_path):
    """finish() writes the PNG with figures.save_png (one drawing pass, zlib level 3), not savefig (which draws a
    constrained-layout figure twice): the decoded pixels of a new figure must be those savefig(dpi=DPI) writes of
    the same new figure (a figure drawn before is laid out again from where it was), and the figure keeps its dpi
    and canvas."""
    import matplotlib.image as mpimg

    from afmkit.figures import DPI, save_png

    def new_figure(layout):
        fig, axes = plt.subplots(2, 2, figsize=(5, 3.5), layout=layout, sharex=True)
        x = np.linspace(0.1, 10, 500)
        axes[0, 0].semilogy(x, np.exp(-x), label="exp(−x)")
        axes[0, 1].plot(x, np.sin(x))
        mesh = axes[1, 0].pcolormesh(np.outer(np.sin(x[:40]), np.cos(x[:30])), rasterized=True)
        axes[1, 1].set_title("τ_c [T]")
        axes[0, 0].legend()
        fig.colorbar(mesh, ax=axes[1, 0], label="Re s [Ω]")
        return fig

    for layout in ("constrained", None):
        new_figure(layout).savefig(tmp_path / "savefig.png", dpi=DPI)
        fig = new_figure(layout)
        dpi, canvas = fig.dpi, fig.canvas
        save_png(fig, tmp_path / "once.png")
        assert (fig.dpi, fig.canvas) == (dpi, canvas)
        a, b = mpimg.imread(tmp_path / "savefig.png"), mpimg.imread(tmp_path / "once.png")
        assert a.shape == b.shape and np.array_equal(a, b), layout
        plt.close("all")
