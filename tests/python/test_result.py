"""afmkit.Result as people already use tables (docs/python.md#the-result-object): a read-only mapping of columns,
attribute access, bool flags, pandas and xarray with units, an HTML view. Small runs (well under a second each)."""
import copy
import json
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import afmkit
from afmkit import _afmkit


@pytest.fixture(scope="module")
def sweep():
    return afmkit.tapping.sweep(separation_min=7.0, separation_max=9.0, points=4, mode="instrument", quiet=True)


@pytest.fixture(scope="module")
def chart():
    # delays not in increasing order, a non-square grid: the re-gridding must not rely on either
    return afmkit.control.chart(harmonics=2, x_points=5, y_points=4, delays=[0.3, 0.1, 0.2], boundaries_output="",
                                progress=False)


def test_the_mapping_protocol_gives_the_columns(sweep):
    d = dict(sweep)
    assert list(d) == sweep.columns == list(sweep) == list(sweep.keys())
    for c in sweep.columns:
        assert d[c] is sweep[c] and getattr(sweep, c) is sweep[c]
    assert len(sweep) == 8 == len(sweep["amplitude"])  # rows, as before (and as a DataFrame's)
    assert len(sweep.keys()) == len(sweep.columns)
    assert "amplitude" in sweep and "nothing" not in sweep
    assert [k for k, _ in sweep.items()] == sweep.columns
    assert sweep.get("nothing") is None
    with pytest.raises(KeyError, match="no column 'nothing'"):
        sweep["nothing"]
    with pytest.raises(AttributeError, match="nothing"):
        sweep.nothing
    for change in (lambda: sweep.__setitem__("amplitude", 1), lambda: sweep.pop("amplitude"),
                   lambda: sweep.update(x=1), lambda: sweep.__delitem__("amplitude"), sweep.clear):
        with pytest.raises(TypeError, match="read-only"):
            change()
    assert sweep.columns[0] == "separation"  # unchanged by the attempts


def test_old_uses_keep_working(sweep):
    assert sweep.table["amplitude"] is sweep["amplitude"] and set(sweep.table) == set(sweep.columns)
    assert sweep.units["amplitude"] == "L" and sweep.meaning["amplitude"]
    assert sweep.results["rows"] == len(sweep) and sweep.results.rows == len(sweep)
    assert "afmkit.Result of tapping sweep: 8 rows" in repr(sweep)


def test_the_summary_reads_as_attributes():
    r = afmkit.control.roots(harmonics=3)
    assert r.results.box.real_min == r.results["box"]["real_min"]
    assert isinstance(r.results, dict)
    with pytest.raises(AttributeError, match="no summary result 'nothing'"):
        r.results.nothing


def test_flags_are_booleans_equal_to_the_command_lines_0_1(sweep):
    assert sweep.stable.dtype == bool and sweep.jumped.dtype == bool and sweep.periodic.dtype == bool
    # independently: stable means every Floquet multiplier inside the unit circle (the column's definition)
    ok = np.isfinite(sweep.floquet_max)
    assert np.array_equal(sweep.stable[ok], sweep.floquet_max[ok] < 1)
    assert sweep.amplitude[sweep.stable].size == np.count_nonzero(sweep.stable)  # usable as a mask
    flags = [c for c in sweep.columns if sweep.units[c].startswith("boolean")]
    assert set(flags) == {"stable", "periodic", "jumped", "trapped"}
    assert all(sweep[c].dtype == bool for c in flags)
    assert all(sweep[c].dtype != bool for c in sweep.columns if c not in flags)


def test_pandas_dataframe_and_to_pandas(sweep):
    pd = pytest.importorskip("pandas")
    df = pd.DataFrame(sweep)
    assert list(df.columns) == sweep.columns and len(df) == len(sweep)
    assert df["stable"].dtype == bool
    np.testing.assert_array_equal(df["amplitude"].to_numpy(), sweep.amplitude)
    df = sweep.to_pandas()
    assert df.attrs["units"] == sweep.units and df.attrs["meaning"] == sweep.meaning
    assert df.attrs["command"] == "tapping sweep" and df.attrs["params"] == sweep.params
    assert df.attrs["results"]["rows"] == len(sweep)


def test_to_xarray_of_a_chart_is_the_long_table_regridded(chart):
    ds = chart.to_xarray()
    assert chart.results["x"] == "alpha" and chart.results["y"] == "beta"
    assert ds.spectral_abscissa.dims == ("delay", "beta", "alpha")
    assert ds.sizes == {"delay": 3, "beta": 4, "alpha": 5}
    # independently of to_xarray: each row's value at its (delay, y, x) coordinates
    for i in range(len(chart)):
        at = dict(delay=chart.delay[i], beta=chart.y[i], alpha=chart.x[i])
        for c in ("spectral_abscissa", "unstable_roots", "region"):
            v = ds[c].sel(at).item()
            assert v == chart[c][i] or (np.isnan(v) and np.isnan(chart[c][i])), (c, i)
    np.testing.assert_array_equal(ds.delay.values, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(ds.alpha.values, np.unique(chart.x))
    assert ds.alpha.attrs["units"] == "Omega" and "alpha" in ds.alpha.attrs["long_name"]
    assert ds.delay.attrs["units"] == "T"
    assert ds.spectral_abscissa.attrs == {"units": chart.units["spectral_abscissa"],
                                          "long_name": chart.meaning["spectral_abscissa"]}
    assert ds.attrs["command"] == "control chart"


def test_a_chart_declares_its_grid_in_the_result_and_the_sidecar(chart, tmp_path):
    import json
    g = chart.grid
    assert g["dims"] == ["delay", "beta", "alpha"] and g["columns"] == ["delay", "y", "x"] and g["shape"] == [3, 4, 5]
    # independently: the coordinates are the columns' distinct values (delays in the order given)
    np.testing.assert_array_equal(g["coords"]["delay"], [0.3, 0.1, 0.2])
    np.testing.assert_array_equal(g["coords"]["alpha"], np.unique(chart.x))
    np.testing.assert_array_equal(g["coords"]["beta"], np.unique(chart.y))
    # and the rows are that grid in row-major order (x fastest)
    np.testing.assert_array_equal(chart.x, np.tile(np.unique(chart.x), 12))
    np.testing.assert_array_equal(chart.delay, np.repeat([0.3, 0.1, 0.2], 20))
    assert pickle.loads(pickle.dumps(chart)).grid == g
    path = tmp_path / "chart.csv"
    afmkit.control.chart(harmonics=2, x_points=5, y_points=4, delays=[0.3, 0.1, 0.2], boundaries_output="",
                         progress=False, output=str(path))
    with open(f"{path}.json") as f:
        assert json.load(f)["grid"] == g
    assert afmkit.control.tf(harmonics=3, points=7).grid is None  # a table along one variable declares none


def test_to_xarray_of_a_margin_map_and_of_tables():
    m = afmkit.control.chart(controller="single", harmonics=2, x_points=3, y_points=2, quantity="margin",
                             boundaries_output="", progress=False).to_xarray()
    assert m.critical_delay.dims == ("b", "a")
    tf = afmkit.control.tf(harmonics=3, points=7).to_xarray()
    assert tf.magnitude.dims == ("frequency",) and tf.frequency.attrs["units"] == "Omega"
    hb = afmkit.tapping.hb(points=30)
    ds = hb.to_xarray()
    assert ds.amplitude.dims == ("row",) and ds.sizes["row"] == len(hb)
    assert list(ds.branch.values) == list(hb.branch)


def test_html_shows_names_units_and_the_summary(sweep):
    html = sweep._repr_html_()
    assert html.startswith("<div>") and html.count("<th title=") == len(sweep.columns)
    assert "<small>L</small>" in html and "tapping sweep" in html and "rows" in html
    long = afmkit.tapping.hb(points=100)._repr_html_()
    assert "more rows" in long and long.count("<tr><td>") == 10  # head and tail rows only


def test_a_result_copies_and_pickles(sweep):
    for other in (pickle.loads(pickle.dumps(sweep)), copy.copy(sweep), copy.deepcopy(sweep)):
        assert other.columns == sweep.columns and other.params == sweep.params and other.units == sweep.units
        assert all(np.array_equal(other[c], sweep[c]) for c in sweep.columns)
        assert other.results.rows == sweep.results.rows


def test_the_module_imports_without_pandas_and_xarray_and_says_what_is_missing():
    code = ("import sys; sys.modules['pandas'] = None; sys.modules['xarray'] = None\n"
            "import afmkit\nr = afmkit.control.tf(harmonics=2, points=3)\n"
            "for f in (r.to_pandas, r.to_xarray):\n"
            "    try:\n        f()\n    except ImportError as e:\n        print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "to_pandas() needs pandas" in out and "to_xarray() needs xarray" in out


def test_a_sweep_in_another_parameter_describes_each_column_by_its_name():
    # the columns used to be renamed by position after the swept parameter was put first: direction had the
    # separation's meaning and amplitude the directions' (fixed by declaring each column with its value)
    r = afmkit.tapping.sweep(parameter="drive_frequency", parameter_min=0.95, parameter_max=1.05, points=3, quiet=True)
    assert r.columns[:4] == ["drive_frequency", "separation", "direction", "amplitude"]
    assert "fixed: the sweep moves drive_frequency" in r.meaning["separation"]
    assert r.meaning["direction"].startswith("down (from parameter_max")
    assert r.meaning["amplitude"] == "first-harmonic amplitude B of the periodic orbit"
    assert set(r.direction) <= {"down", "up", "continuation"}


def _timeless(results):
    out = dict(results)
    out["search"] = dict(out["search"], seconds=0.0)  # the search's wall time: the one value two runs differ in
    return out


def test_a_summary_made_where_it_is_read_is_the_document_of_the_run():
    # tapping orbit makes its summary (~550 values: the search report lists every seed) when r.results is first
    # read: a caller reading only the columns does not pay for it (issue 26: the command layer adds <= 5 % to a
    # 1 ms command, bench/command_layer.py). Read, pickled or copied, it is the run's document.
    case = dict(quality_factor=2.0, separation=5.0, max_period_multiple=1)
    r = afmkit.tapping.orbit(**case)
    assert not isinstance(r.__dict__["_results"], dict)  # not made yet
    assert r.columns[0] == "source" and len(r) == 1  # the table, the params, the units without it
    assert r.params["quality_factor"] == 2.0 and r.units["amplitude"] == "L"
    made = r.results
    assert isinstance(made, dict) and made is r.results  # made once, kept
    assert len(made.search.seeds) == made.search.seeds_total > 10 and made.status == "ok"
    assert {"kind", "orbits", "initial_position"} <= set(made.search.seeds[0])
    assert made.units.search.seeds.initial_position == "L"
    # the document the same run gives at once (the --config replay of its record; a result pickled before the
    # summary was read)
    fresh = afmkit.tapping.orbit(**r.params)
    for other in (pickle.loads(pickle.dumps(fresh)), copy.deepcopy(afmkit.tapping.orbit(**case)), fresh):
        assert _timeless(other.results) == _timeless(made)
    out = subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "orbit", "--quality-factor=2", "--separation=5",
                          "--max-period-multiple=1", "--output", "", "--json"], capture_output=True, text=True, check=True)
    printed = json.loads(out.stdout)
    del printed["table"]
    assert _timeless(printed) == _timeless(made)



def test_a_result_made_by_the_module_owns_its_mappings_and_makes_params_when_read(tmp_path):
    # the module makes the Result itself (not Result.__init__), shares the column texts between calls (str objects,
    # immutable) and converts the parameter record when r.params is first read: none of that may show
    case = dict(quality_factor=2.0, separation=5.0, max_period_multiple=1)
    a, b = afmkit.tapping.orbit(**case), afmkit.tapping.orbit(**case)
    assert type(a) is afmkit.Result and a.command == "tapping orbit" and a.grid is None
    assert a.units == b.units and a.units is not b.units and a.meaning is not b.meaning and a.columns is not b.columns
    dict.__setitem__(a.units, "amplitude", "changed")  # a caller's change to one result's mapping stays there
    a.columns.append("x")
    assert b.units["amplitude"] == "L" and b.columns[-1] != "x"
    assert not isinstance(b.__dict__["_params"], dict)  # not made yet
    params = b.params
    assert params is b.params and params["quality_factor"] == 2.0  # made once
    # the record is the command line's (its sidecar), key for key
    out = tmp_path / "orbit.csv"
    cli = os.environ.get("AFMKIT_CLI")
    if cli:
        subprocess.run([cli, "tapping", "orbit", "--quality-factor", "2.0", "--separation", "5.0",
                        "--max-period-multiple", "1", "--output", str(out)], check=True, capture_output=True)
        sidecar = json.loads((tmp_path / "orbit.csv.json").read_text())
        recorded = dict(sidecar["parameters"])
        recorded.pop("json", None)
        recorded["output"] = ""
        assert params == recorded
    # None is "not given", as in the signature; an unknown keyword is refused even when None
    assert afmkit.tapping.orbit(**case, drive_amplitude=None).params == params
    with pytest.raises(TypeError, match="unexpected keyword argument 'nothing'"):
        afmkit.tapping.orbit(**case, nothing=None)


def test_column_texts_kept_from_the_last_call_follow_the_columns_of_this_one():
    # the module keeps a command's column names/units/meanings from its last call and copies them when this call's
    # columns have the same texts: a call with other columns (a sweep in another parameter) must get its own
    plain = dict(points=3, quiet=True)
    moved = dict(parameter="drive_frequency", parameter_min=0.95, parameter_max=1.05, points=3, quiet=True)
    for kwargs, first in ((plain, "separation"), (moved, "drive_frequency"), (plain, "separation"),
                          (plain, "separation"), (moved, "drive_frequency")):
        r = afmkit.tapping.sweep(**kwargs)
        assert r.columns[0] == first and list(r) == r.columns == list(r.units) == list(r.meaning)
        assert ("fixed: the sweep moves drive_frequency" in r.meaning["separation"]) == (first != "separation")


def test_a_record_made_when_read_is_the_runs_own_however_many_results_are_kept():
    # a Result holds the parameter set its run used until r.params is first read (a command lends at most a few
    # sets; beyond, the record is made at once): no other run may change what a kept Result records
    kept = [afmkit.tapping.orbit(quality_factor=2.0 + 0.25 * i, separation=5.0, max_period_multiple=1)
            for i in range(12)]
    assert sum(not isinstance(r.__dict__["_params"], dict) for r in kept) == 12  # none made yet
    for i, r in reversed(list(enumerate(kept))):  # read in another order than made
        assert r.params["quality_factor"] == 2.0 + 0.25 * i and r.params["separation"] == 5.0
    again = afmkit.tapping.orbit(**kept[5].params)
    assert again.params == kept[5].params and np.array_equal(again.amplitude, kept[5].amplitude)
    del kept  # the lent sets go back: later runs record as before
    assert afmkit.tapping.orbit(quality_factor=3.0, separation=5.0).params["quality_factor"] == 3.0
