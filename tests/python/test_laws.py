"""afmkit.laws: force-law objects handed to the commands (issue 26 §4, docs/python.md#force-laws). A law object gives
the same run as the keywords it stands for; a table from arrays gives the same run as the file written by hand;
the record replays; bad values are refused naming the key."""
import os

import numpy as np
import pytest

import afmkit
from afmkit import laws

CANTILEVER = dict(spring_constant=40.0, resonance_frequency=300.0, quality_factor=400.0, free_amplitude=10.0)


def same_table(a, b):
    assert a.columns == b.columns
    for c in a.columns:
        assert np.asarray(a[c]).tobytes() == np.asarray(b[c]).tobytes(), c


def test_every_registry_law_has_a_class():
    names = {spec["name"] for spec in afmkit._afmkit.laws()}
    assert names == {getattr(laws, n).name for n in laws.__all__ if n != "Law"}


def test_a_law_object_runs_as_its_keywords():
    law = laws.DMT(hamaker=1e-19, effective_modulus=2.0, tip_radius=10.0)
    by_object = afmkit.tapping.orbit(law=law, separation=8.0, **CANTILEVER)
    by_keywords = afmkit.tapping.orbit(units="physical", law="dmt", hamaker=1e-19, effective_modulus=2.0,
                                       tip_radius=10.0, separation=8.0, **CANTILEVER)
    same_table(by_object, by_keywords)
    assert by_object.params == by_keywords.params
    assert by_object.params["departure_hamaker"] == 1e-19  # follows hamaker: recorded as used


def test_a_piecewise_linear_law_keeps_the_commands_units():
    law = laws.Attractive(approach_stiffness=10.0, departure_stiffness=5.0, approach_adhesion=0.5,
                          departure_adhesion=1.0)
    r = afmkit.tapping.hb(law=law, points=40)
    assert r.params["units"] == "normalised" and r.params["departure_stiffness"] == 5.0


def test_bad_law_values_are_refused_naming_the_key():
    with pytest.raises(ValueError, match="hamaker = -1 is out of range"):
        laws.DMT(hamaker=-1.0)
    with pytest.raises(ValueError, match="restitution is not a key of law dmt"):
        laws.DMT(restitution=0.5)
    with pytest.raises(ValueError, match="hamaker must be a number"):
        laws.DMT(hamaker="1e-19")
    with pytest.raises(ValueError, match="hamaker is given both"):
        afmkit.tapping.orbit(law=laws.DMT(hamaker=1e-19), hamaker=2e-19, separation=8.0, **CANTILEVER)


def _dmt_table():
    # a DMT curve (E* = 1 GPa, R = 10 nm, A_H = 1e-19 J, a0 = 0.3 nm) as a conservative table, SI units
    d = np.linspace(0.0, 20e-9, 81)
    attraction = -1e-19 * 10e-9 / (6.0 * np.maximum(d, 0.3e-9) ** 2)
    approach = attraction + 4.0 / 3.0 * 1e9 * np.sqrt(10e-9) * np.clip(0.3e-9 - d, 0.0, None) ** 1.5
    return d, approach, approach.copy()


def test_a_table_from_arrays_runs_as_its_file(tmp_path, monkeypatch):
    monkeypatch.setenv("AFMKIT_LAW_CACHE", str(tmp_path / "cache"))
    d, approach, retract = _dmt_table()
    table = laws.Table(d, approach)  # retract omitted: the same as approach
    assert table == laws.Table(d, approach, retract)
    by_object = afmkit.tapping.orbit(law=table, separation=8.0, **CANTILEVER)
    path = tmp_path / "law.csv"
    path.write_text(table.text())
    by_file = afmkit.tapping.orbit(units="physical", law="table", force_curve=str(path), separation=8.0, **CANTILEVER)
    same_table(by_object, by_file)
    # the record names a file holding exactly these values, named by content: it replays
    recorded = by_object.params["force_curve"]
    assert os.path.dirname(recorded) == str(tmp_path / "cache")
    assert open(recorded).read() == table.text()
    assert laws.Table(d, approach, retract).path() == recorded
    same_table(afmkit.tapping.orbit(**by_object.params), by_object)


def test_a_table_refuses_bad_arrays():
    d, approach, retract = _dmt_table()
    with pytest.raises(ValueError, match="retract has 3 values and distance 81"):
        laws.Table(d, approach, retract[:3])
    bad = approach.copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match=r"approach\[5\] = nan is not finite"):
        laws.Table(d, bad)


def test_a_reconstruction_hands_its_law_to_the_tapping_commands(tmp_path, monkeypatch):
    monkeypatch.setenv("AFMKIT_LAW_CACHE", str(tmp_path))
    # van der Waals sphere–plane Δf (first order, A ≫ d): a smooth attractive curve
    z = np.linspace(0.5e-9, 10e-9, 60)
    k, f0, amplitude, c = 40.0, 300e3, 2e-9, 1e-19 * 10e-9 / 6.0
    u = np.linspace(-1.0, 1.0, 4001)[1:-1]
    w = u / np.sqrt(1.0 - u * u)
    df = np.array([-(f0 / (np.pi * k * amplitude)) * np.trapz(-c / (zi + amplitude * (1 + u)) ** 2 * w, u) for zi in z])
    r = afmkit.spectroscopy.reconstruct_fm(z, df, spring_constant=k, resonance_frequency=f0, amplitude=amplitude,
                                           round_trip=False)
    table = r.table
    assert isinstance(table, laws.Table)
    np.testing.assert_allclose(table.distance, r.law["distance"])
    orbit = afmkit.tapping.orbit(law=table, separation=6.0, **CANTILEVER)
    assert len(orbit) > 0 and orbit.params["law"] == "table"
