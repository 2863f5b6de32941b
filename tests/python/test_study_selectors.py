"""Study output selectors (docs/study.md#outputs): aggregates over the table and over results lists, filters by
field, sorted fold and jump records, and the unit of every output. Each expected value is computed here from the
command's own table and records (afmkit.tapping.sweep / hb / orbit), not copied from a study."""
import math

import numpy as np
import pytest

import afmkit
from afmkit import _afmkit
from afmkit.study import Study, run

# law (26) of seed 1, demo case: one approach jump (grazing) and one retract jump (fold); the continuation adds
# the fold of the contact branch
SWEEP = {"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0, "frequency_ratio": 0.99,
         "separation_min": 8.4, "separation_max": 10.4, "points": 17, "mode": "both"}
HB = {"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0, "frequency_ratio": 0.99,
      "quality_factor": 100.0}
ORBIT = {"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0, "frequency_ratio": 0.99,
         "separation": 9.5}


def evaluate(command, params, outputs):
    """The outputs at one point (no axes), as evaluate_points computes them in a study chunk."""
    values, failed = _afmkit.evaluate_points(command, dict(params), [], np.zeros((1, 0)), list(outputs))
    assert failed == 0
    return dict(zip(outputs, values[0]))


def units(command, params, outputs):
    return dict(zip(outputs, _afmkit.output_units(command, dict(params), [], np.zeros((1, 0)), list(outputs))))


@pytest.fixture(scope="module")
def sweep():
    return afmkit.tapping.sweep(**SWEEP)


def test_count_counts_true_values_not_rows(sweep):
    jumped = sweep["jumped"] == 1
    assert 0 < jumped.sum() < len(sweep)  # a case where the two differ
    got = evaluate("tapping sweep", SWEEP, ["count(jumped)", "sum(jumped)", "count(amplitude)",
                                            "count(amplitude | jumped)", "count(hb_amplitude)", "count(stable)"])
    assert got["count(jumped)"] == jumped.sum()
    assert got["sum(jumped)"] == jumped.sum()
    assert got["count(amplitude)"] == np.isfinite(sweep["amplitude"]).sum()  # defined numbers
    assert got["count(amplitude | jumped)"] == np.isfinite(sweep["amplitude"][jumped]).sum()
    assert got["count(hb_amplitude)"] == np.isfinite(sweep["hb_amplitude"]).sum()
    assert got["count(stable)"] == (sweep["stable"] == 1).sum()


def test_sweep_folds_and_jumps_are_records_sorted_by_separation_with_branch_and_kind(sweep):
    folds, jumps = sweep.results["folds"], sweep.results["jumps"]
    assert folds and jumps
    for records in (folds, jumps):
        seps = [r["separation"] for r in records]
        assert seps == sorted(seps)
    for f in folds:
        assert f["kind"] in ("maximum", "minimum") and f["branch"] in ("free", "contact")
        assert set(f) >= {"separation", "amplitude", "offset", "phase", "branch", "kind"}  # the shape of hb's folds
    for j in jumps:
        assert j["direction"] in ("approach", "retract") and j["branch"] in ("free", "contact")
    # the lists of separations are the jump records' separations, per direction
    for d in ("approach", "retract"):
        assert sorted(sweep.results[f"{d}_jumps"]) == sorted(j["separation"] for j in jumps if j["direction"] == d)
    # the rows marked jumped: the first grid point past each jump, in sweep order
    for d in ("approach", "retract"):
        rows = sweep["direction"] == d
        seps, marked = sweep["separation"][rows], sweep["jumped"][rows] == 1
        for j in (j for j in jumps if j["direction"] == d):
            past = seps < j["separation"] if d == "approach" else seps > j["separation"]
            assert marked[np.argmax(past)], (d, j["separation"])


def test_aggregates_and_filters_over_results_lists(sweep):
    folds, jumps = sweep.results["folds"], sweep.results["jumps"]
    retract = [j for j in jumps if j["direction"] == "retract"]
    approach = [j for j in jumps if j["direction"] == "approach"]
    outputs = ["count(folds)", "min(folds/separation)", "max(folds/separation)", "folds/0/separation",
               "count(folds[kind=maximum])", "count(jumps[direction=retract])", "jumps[direction=retract]/0/separation",
               "jumps[direction=approach]/0/amplitude_after", "count(approach_jumps)", "max(retract_jumps)",
               "first(jumps[direction=retract][branch=contact]/separation)", "count(jumps[direction=sideways])",
               "jumps[direction=sideways]/0/separation", "sum(jumps/amplitude_before)"]
    got = evaluate("tapping sweep", SWEEP, outputs)
    assert got["count(folds)"] == len(folds)
    assert got["min(folds/separation)"] == min(f["separation"] for f in folds)
    assert got["max(folds/separation)"] == max(f["separation"] for f in folds)
    assert got["folds/0/separation"] == min(f["separation"] for f in folds)  # sorted: the first is the smallest
    assert got["count(folds[kind=maximum])"] == sum(f["kind"] == "maximum" for f in folds)
    assert got["count(jumps[direction=retract])"] == len(retract)
    assert got["jumps[direction=retract]/0/separation"] == min(j["separation"] for j in retract)
    assert got["jumps[direction=approach]/0/amplitude_after"] == min(approach, key=lambda j: j["separation"])[
        "amplitude_after"]
    assert got["count(approach_jumps)"] == len(sweep.results["approach_jumps"])
    assert got["max(retract_jumps)"] == max(sweep.results["retract_jumps"])
    contact = [j["separation"] for j in retract if j["branch"] == "contact"]
    assert contact  # the retract leaves the contact branch at its fold
    assert got["first(jumps[direction=retract][branch=contact]/separation)"] == contact[0]
    assert got["count(jumps[direction=sideways])"] == 0  # nothing matches: count 0, a value NaN
    assert math.isnan(got["jumps[direction=sideways]/0/separation"])
    assert got["sum(jumps/amplitude_before)"] == pytest.approx(sum(j["amplitude_before"] for j in jumps), rel=1e-15)


def test_hb_folds_are_sorted_by_separation():
    hb = afmkit.tapping.hb(**HB)
    folds = hb.results["folds"]
    assert len(folds) >= 2
    seps = [f["separation"] for f in folds]
    assert seps == sorted(seps)
    got = evaluate("tapping hb", HB, ["folds/0/separation", "max(folds/separation)", "count(folds[kind=maximum])",
                                      "folds[kind=maximum]/0/separation"])
    assert got["folds/0/separation"] == min(seps)
    assert got["max(folds/separation)"] == max(seps)
    assert got["count(folds[kind=maximum])"] == sum(f["kind"] == "maximum" for f in folds)
    assert got["folds[kind=maximum]/0/separation"] == min(f["separation"] for f in folds if f["kind"] == "maximum")


def test_orbit_records_filtered_by_a_boolean_field():
    r = afmkit.tapping.orbit(**ORBIT)
    stable = r["stable"] == 1
    got = evaluate("tapping orbit", ORBIT, ["count(orbits[stable=true])", "count(orbits[stable=false])",
                                            "max(orbits[stable=true]/amplitude)", "count(amplitude | stable)"])
    assert got["count(orbits[stable=true])"] == stable.sum() == got["count(amplitude | stable)"]
    assert got["count(orbits[stable=false])"] == (~stable).sum()
    assert got["max(orbits[stable=true]/amplitude)"] == r["amplitude"][stable].max()


def test_every_output_has_its_unit():
    physical = {"units": "physical", "law": "dmt", "separation_min": 8.0, "separation_max": 12.0, "points": 5,
                "mode": "both"}
    got = units("tapping sweep", physical,
                ["approach_jumps/0", "jumps/0/separation", "min(folds/separation)", "folds/0/phase", "count(folds)",
                 "count(jumped)", "sum(jumped)", "max(amplitude)", "max(energy_dissipated)", "free_amplitude",
                 "jump_tolerance", "rows", "jumps/0/located"])
    assert got == {"approach_jumps/0": "nm", "jumps/0/separation": "nm", "min(folds/separation)": "nm",
                   "folds/0/phase": "rad", "count(folds)": "count", "count(jumped)": "count", "sum(jumped)": "count",
                   "max(amplitude)": "nm", "max(energy_dissipated)": "aJ", "free_amplitude": "nm",
                   "jump_tolerance": "nm", "rows": "count", "jumps/0/located": "boolean (0/1)"}
    assert units("tapping hb", HB, ["folds/0/separation", "free_amplitude", "folds/0/q"]) == {
        "folds/0/separation": "L", "free_amplitude": "L", "folds/0/q": "dimensionless"}
    assert units("tapping orbit", ORBIT, ["free_amplitude", "orbits/0/peak_force", "search/seeds_by_kind/grid",
                                          "orbits/0/floquet_multipliers/0/re"]) == {
        "free_amplitude": "L", "orbits/0/peak_force": "L/t^2", "search/seeds_by_kind/grid": "count",
        "orbits/0/floquet_multipliers/0/re": "dimensionless"}
    # a record's own "units" (control margin: tau0/units) names its numbers
    assert units("control margin", {}, ["tau0/beta_critical", "critical_delay"]) == {
        "tau0/beta_critical": "Omega", "critical_delay": "T"}


def _numeric_leaves(doc, path=()):
    """Every path to a number in a results document, list indices as 0 (one per list)."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if not path and k == "units":
                continue
            yield from _numeric_leaves(v, path + (k,))
    elif isinstance(doc, list):
        if doc:
            yield from _numeric_leaves(doc[0], path + ("0",))
    elif isinstance(doc, (int, float)) and not isinstance(doc, bool) or doc in ("inf", "-inf"):
        yield "/".join(path)


@pytest.mark.parametrize("command,params", [("tapping sweep", SWEEP), ("tapping hb", HB), ("tapping orbit", ORBIT)])
def test_every_number_a_tapping_command_reports_has_a_unit(command, params):
    results = getattr(afmkit.tapping, command.split()[1])(**params).results
    paths = sorted(set(_numeric_leaves(results)))
    assert paths
    got = units(command, params, paths)
    assert not [p for p, u in got.items() if not u], got


def test_a_study_records_the_units_and_the_values(tmp_path, sweep):
    study = Study.make("tapping.sweep", axes={"points": [17]}, outputs=["count(jumped)", "folds/0/separation",
                                                                        "count(jumps[direction=approach])"],
                       parameters={k: v for k, v in SWEEP.items() if k != "points"})
    ds = run(study, tmp_path / "s.zarr", scheduler="serial", progress=False).load()
    assert ds["count_jumped"].attrs["units"] == "count"
    assert ds["folds_0_separation"].attrs["units"] == "L"
    assert int(ds["count_jumped"].values[0]) == (sweep["jumped"] == 1).sum()
    assert float(ds["folds_0_separation"].values[0]) == min(f["separation"] for f in sweep.results["folds"])


@pytest.mark.parametrize("output,message", [
    ("folds/separation", "aggregate"),
    ("approach_jumps", "is a list"),
    ("folds/0", "is a record"),
    ("count(folds | stable)", "[field=value]"),
    ("count(nothing)", "no column 'nothing'"),
    ("folds[kind]/0/separation", "[field=value]"),
    ("median(amplitude)", "unknown aggregate"),
])
def test_bad_selectors_are_refused_with_the_reason(output, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("|", r"\|")):
        evaluate("tapping sweep", {**SWEEP, "mode": "both"}, [output])
