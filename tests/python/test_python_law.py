"""afmkit.laws.Python: force laws written in Python (issue 26 §4, docs/force-laws.md#python). A Python law equal to a
built-in law gives the same orbits (to integration tolerance) and the same HB curves; every law's force() equals its
closed form, with the branch the velocity selects and the Kelvin–Voigt term; a callable that raises, returns the
wrong shape or a value that is not finite is refused naming it, also when called during a run (GIL released)."""
import threading
import time

import numpy as np
import pytest

import afmkit
from afmkit import laws

CANTILEVER = dict(spring_constant=40.0, resonance_frequency=300.0, quality_factor=10.0, free_amplitude=10.0)
KA, KB = 400.0, 320.0  # N/m: the seed's linear hysteresis (seed-1 eq. 11) in physical units
E, R, A, A0 = 1e9, 10e-9, 1e-19, 0.165e-9  # DMT in SI: E* [Pa], R [m], A_H [J], a0 [m]


def seed_approach(d):
    return np.where(d < 0, -KA * d, 0.0)


def seed_departure(d):
    return np.where(d < 0, -KB * d, 0.0)


SEED = dict(law="hysteresis", units="physical", sample_stiffness_approach=KA, sample_stiffness_departure=KB)


def dmt_si(d):
    """DMT (docs/force-laws.md) in SI, written independently of the C++ law."""
    d = np.asarray(d, dtype=float)
    return -A * R / (6.0 * np.maximum(d, A0) ** 2) + 4.0 / 3.0 * E * np.sqrt(R) * np.clip(A0 - d, 0.0, None) ** 1.5


@pytest.fixture(scope="module")
def seed_law():
    return laws.Python(approach=seed_approach, departure=seed_departure, switching_gaps=[0.0])


def test_a_python_law_gives_the_orbits_of_the_same_builtin_law(seed_law):
    builtin = afmkit.tapping.orbit(separation=8.0, **SEED, **CANTILEVER)
    ticks, done = [0], threading.Event()

    def other_thread():  # runs while the orbit search does: the run holds no GIL (no Python inside the domain)
        while not done.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    thread = threading.Thread(target=other_thread)
    thread.start()
    try:
        python = afmkit.tapping.orbit(law=seed_law, separation=8.0, **CANTILEVER)
    finally:
        done.set()
        thread.join()
    assert ticks[0] >= 10
    assert python.params["law"] == "python" and python.params["units"] == "physical"
    assert len(python) == len(builtin) >= 1
    # the built-in law flows in closed form, the Python law is integrated: equal to the integration tolerance
    np.testing.assert_allclose(python["amplitude"], builtin["amplitude"], rtol=1e-7)
    np.testing.assert_allclose(python["phase"], builtin["phase"], atol=1e-7)
    np.testing.assert_allclose(python["peak_force"], builtin["peak_force"], rtol=1e-6)
    np.testing.assert_allclose(python["energy_dissipated"], builtin["energy_dissipated"], rtol=1e-6)


def test_a_python_law_gives_the_hb_curves_of_the_same_builtin_law(seed_law):
    builtin = afmkit.tapping.hb(separation=8.0, points=40, **SEED, **CANTILEVER)
    python = afmkit.tapping.hb(law=seed_law, separation=8.0, points=40, **CANTILEVER)
    assert len(python) == len(builtin) > 0
    for column in ("q", "amplitude", "phase", "offset"):
        np.testing.assert_allclose(python[column], builtin[column], rtol=1e-9, atol=1e-12, err_msg=column)
    dmt = laws.Python(dmt_si, switching_gaps=[A0])
    by_python = afmkit.tapping.hb(law=dmt, separation=8.0, points=30, **CANTILEVER)
    by_builtin = afmkit.tapping.hb(law=laws.DMT(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19),
                                   separation=8.0, points=30, **CANTILEVER)
    np.testing.assert_allclose(by_python["amplitude"], by_builtin["amplitude"], rtol=1e-9)
    np.testing.assert_allclose(by_python["phase"], by_builtin["phase"], atol=1e-9)


def test_the_builtin_laws_force_is_the_closed_form():
    d = np.linspace(-3e-9, 10e-9, 1301)
    b = laws.DMT(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19).force(d)
    np.testing.assert_allclose(b.approach, dmt_si(d), rtol=1e-12, atol=1e-24)
    np.testing.assert_array_equal(b.approach, b.departure)
    np.testing.assert_array_equal(b.damping, 0.0)
    # Kelvin–Voigt: c(d) = η √(R (a0 − d)) in contact; H = H_a − c ḋ
    kv = laws.KelvinVoigt(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19, viscosity=100.0)
    c = 100.0 * np.sqrt(R * np.clip(A0 - d, 0.0, None))
    np.testing.assert_allclose(kv.force(d).damping, c, rtol=1e-12, atol=1e-30)
    np.testing.assert_allclose(kv(d, velocity=-2.0), dmt_si(d) + 2.0 * c, rtol=1e-12, atol=1e-24)
    # the seed's hysteresis law (N/m, nm, nN -> SI): the velocity picks the branch, the mean at zero velocity
    h = laws.Hysteresis(approach_stiffness=KA, departure_stiffness=KB)
    np.testing.assert_allclose(h(d, -1.0), seed_approach(d), rtol=1e-14)
    np.testing.assert_allclose(h(d, +1.0), seed_departure(d), rtol=1e-14)
    np.testing.assert_allclose(h(d, 0.0), 0.5 * (seed_approach(d) + seed_departure(d)), rtol=1e-14)
    assert h(np.zeros((2, 3)), 1.0).shape == (2, 3)
    # a table with the memory of contact: departing, the retract branch only once in contact
    z = np.linspace(-2e-9, 20e-9, 45)
    table = laws.Table(z, dmt_si(z), np.where(z < 1e-9, 1.3 * dmt_si(z), dmt_si(z)))
    np.testing.assert_allclose(table(z, 1.0, in_contact=False), dmt_si(z), rtol=1e-12, atol=1e-24)
    np.testing.assert_allclose(table(z, 1.0), table.retract, rtol=1e-12, atol=1e-24)
    np.testing.assert_allclose(table.force(z).approach, dmt_si(z), rtol=1e-12, atol=1e-24)


def test_a_python_laws_force_is_its_callables_within_the_stated_tolerance():
    def damping(d):
        return 1e-6 / (1.0 + (d / 1e-9) ** 2)

    law = laws.Python(dmt_si, departure=lambda d: 1.5 * dmt_si(d), damping=damping, switching_gaps=[A0])
    rng = np.random.default_rng(26)
    d = np.concatenate([rng.uniform(-20e-9, 50e-9, 20000), rng.uniform(-1e-6, 1e-4, 2000), [A0, 0.0, -1e-3, 1.0]])
    b = law.force(d)
    # 1e-12 of the largest force on each base interval: bound it by the largest force within a factor 2 of d
    scale = np.abs(dmt_si(np.minimum(d / 2, d * 2)))
    assert np.all(np.abs(b.approach - dmt_si(d)) <= 1e-11 * scale + 1e-30)
    assert np.all(np.abs(b.departure - 1.5 * dmt_si(d)) <= 1.5e-11 * scale + 1e-30)
    np.testing.assert_allclose(b.damping, damping(d), rtol=1e-10)
    v = rng.normal(size=d.size)
    expected = np.where(v < 0, dmt_si(d), 1.5 * dmt_si(d)) - damping(d) * v
    np.testing.assert_allclose(law.force(d, v), expected, rtol=1e-10, atol=1e-11 * np.abs(expected).max())
    # beyond the domain the callable itself
    far = laws.Python(dmt_si, switching_gaps=[A0], domain=(-1e-9, 1e-8))
    np.testing.assert_allclose(far.force(np.array([2e-8, 5e-6])).approach, dmt_si(np.array([2e-8, 5e-6])),
                               rtol=1e-15)
    assert far.contact_gap() == pytest.approx(A0) and list(far.switching_gaps()) == pytest.approx([A0])


def test_a_constant_damping_and_an_endpoint_singularity_are_tabulated():
    # √δ at the contact edge (Kelvin–Voigt-like damping): next to a switching gap the series are in √|d − g|, so
    # it is tabulated to the edge, with a handful of pieces and no call into Python during runs
    law = laws.Python(dmt_si, damping=lambda d: 1e-3 * np.sqrt(np.clip(A0 - d, 0.0, None)), switching_gaps=[A0])
    assert law.tabulation["damping"]["direct"] == 0 and law.tabulation["damping"]["pieces"] < 150
    d = A0 - np.geomspace(1e-20, 1e-9, 200)
    c = 1e-3 * np.sqrt(A0 - d)
    # within 1e-10 of the damping's scale on the base interval (0.125, 0.165) nm (the series is checked at its
    # midpoints to 1e-12; next to a singularity the error between them is larger)
    assert np.all(np.abs(law.force(d).damping - c) <= 1e-10 * 1e-3 * np.sqrt(0.04e-9))
    # at the edge: exact but for the rounding of the distance to nm (the law's unit inside), an ulp of a0 in δ
    sliver = A0 - np.geomspace(1e-22, 1e-16, 20)
    assert np.all(np.abs(law.force(sliver).damping - 1e-3 * np.sqrt(A0 - sliver)) <= 1e-3 * np.sqrt(4 * np.spacing(A0)))
    # the callables receive 1-D arrays (code written for a vector of distances works as it is)
    def one_d(d):
        assert d.ndim == 1
        return np.array([dmt_si(x) for x in d[:3]] + list(dmt_si(d[3:])))

    constant = laws.Python(one_d, damping=2e-7, switching_gaps=[A0])
    np.testing.assert_allclose(constant.force(np.array([-1e-9, 1e-9])).damping, 2e-7, rtol=1e-14)


def test_a_callable_that_raises_or_returns_the_wrong_shape_is_refused_naming_it():
    def broken(d):
        raise ZeroDivisionError("no force here")

    with pytest.raises(ValueError, match=r"approach=.*broken raised ZeroDivisionError: no force here"):
        laws.Python(broken)
    with pytest.raises(ValueError, match=r"departure=.*<lambda> returned an array of shape \(\) .*one value per"):
        laws.Python(dmt_si, departure=lambda d: 0.0, switching_gaps=[A0])
    with pytest.raises(ValueError, match=r"returned (inf|nan) at distance .*domain="), np.errstate(divide="ignore"):
        laws.Python(lambda d: 1.0 / d ** 2)
    with pytest.raises(TypeError, match="approach must be a callable"):
        laws.Python(3.0)
    with pytest.raises(TypeError, match="must return numbers"):
        laws.Python(lambda d: np.array(["a"] * d.size, dtype=object).reshape(d.shape))
    with pytest.raises(ValueError, match="damping coefficient must be >= 0"):
        laws.Python(dmt_si, damping=lambda d: -np.ones_like(d), switching_gaps=[A0])
    # a kink not declared as a switching gap cannot be tabulated: named, with the remedy
    with pytest.raises(ValueError, match=r"not smooth near distance 3e-10 m .*switching_gaps"):
        laws.Python(lambda d: np.where(d < 0.3e-9, KA * (0.3e-9 - d), 0.0))


def test_a_callable_failing_during_a_run_is_the_users_error_not_a_crash():
    calls = []

    def short_range(d):  # defined on its domain only; the orbit reaches 18 nm
        calls.append(np.max(d))
        if np.any(d > 6e-9):
            raise RuntimeError("beyond my range")
        return seed_approach(d)

    law = laws.Python(short_range, switching_gaps=[0.0], domain=(-5e-9, 5e-9))
    with pytest.raises(afmkit.InvalidParameter, match=r"approach=.*short_range raised RuntimeError: beyond my range "
                                                      r"at distance") as e:
        afmkit.tapping.orbit(law=law, separation=8.0, **CANTILEVER)
    assert e.value.parameter == "law"
    bad_shape = laws.Python(lambda d: np.where(d < 0, -KA * d, 0.0) if np.all(d <= 5e-9) else np.zeros(2),
                            switching_gaps=[0.0], domain=(-5e-9, 5e-9))
    with pytest.raises(afmkit.InvalidParameter, match="must return one number per distance"):
        afmkit.tapping.orbit(law=bad_shape, separation=8.0, **CANTILEVER)

    def interrupted(d):  # Ctrl-C while the callable runs: the run stops with KeyboardInterrupt, as any run
        if np.any(d > 6e-9):
            raise KeyboardInterrupt
        return seed_approach(d)

    with pytest.raises(KeyboardInterrupt):
        afmkit.tapping.orbit(law=laws.Python(interrupted, switching_gaps=[0.0], domain=(-5e-9, 5e-9)), separation=8.0,
                             **CANTILEVER)


def test_a_python_law_that_creates_energy_needs_the_opt_in_as_a_builtin_one():
    gain = laws.Python(seed_approach, departure=lambda d: np.where(d < 0, -1.1 * KA * d, 0.0), switching_gaps=[0.0])
    assert gain.energy_gain is not None and gain.energy_gain[0] < 0
    with pytest.raises(afmkit.InvalidParameter, match=r"departure branch .* lies above its approach branch at "
                                                      r"distance -.* creates energy; give allow_energy_gain=True"):
        afmkit.tapping.hb(law=gain, separation=8.0, points=10, **CANTILEVER)
    with pytest.raises(afmkit.InvalidParameter, match="must be <= approach_stiffness"):  # the built-in law alike
        afmkit.tapping.hb(separation=8.0, points=10, **{**SEED, "sample_stiffness_departure": 1.1 * KA},
                          **CANTILEVER)
    assert len(afmkit.tapping.hb(law=gain, allow_energy_gain=True, separation=8.0, points=10, **CANTILEVER)) > 0
    assert laws.Python(seed_approach, departure=seed_departure, switching_gaps=[0.0]).energy_gain is None


def test_law_python_without_its_object_and_commands_that_fit_a_law_are_refused():
    with pytest.raises(afmkit.InvalidParameter, match=r"law = python is a force law written in Python"):
        afmkit.tapping.orbit(law="python", units="physical", separation=8.0, **CANTILEVER)
    fit = afmkit.make_command("spectroscopy fit")  # fits the parameters of a registry law: a Python law has none
    with pytest.raises(afmkit.InvalidParameter, match="applies only to the commands that simulate"):
        fit(law=laws.Python(dmt_si, switching_gaps=[A0]))


def test_every_law_plots_its_branches():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = np.linspace(0.0, 20e-9, 81)
    for law in (laws.JKR(), laws.Table(d, dmt_si(d), 1.2 * dmt_si(d)),
                laws.Python(dmt_si, departure=lambda x: 1.5 * dmt_si(x), switching_gaps=[A0])):
        fig, ax = plt.subplots()
        assert law.plot(ax=ax) is ax
        assert len(ax.lines) >= 3  # approach, departure (differs), zero line
        assert "force (nN)" in ax.get_ylabel()
        plt.close(fig)


def test_a_python_law_of_module_functions_pickles_and_runs_the_same_orbit():
    # multiprocessing, Dask and the study runner's workers pickle their arguments: the law travels with its
    # callables and tabulation, and is rebuilt without calling them again; a lambda fails as pickle says
    import pickle

    law = laws.Python(approach=seed_approach, departure=seed_departure, damping=1e-7, switching_gaps=[0.0])
    back = pickle.loads(pickle.dumps(law))
    assert back.tabulation == law.tabulation and back.label == law.label
    d = np.linspace(-2e-9, 2e-9, 41)
    np.testing.assert_array_equal(back.force(d).approach, law.force(d).approach)
    np.testing.assert_array_equal(back.force(d).damping, law.force(d).damping)
    a, b = (afmkit.tapping.orbit(law=x, separation=5.0, **CANTILEVER) for x in (law, back))
    np.testing.assert_array_equal(np.asarray(a["amplitude"]), np.asarray(b["amplitude"]))
    with pytest.raises((pickle.PicklingError, AttributeError)):
        pickle.dumps(laws.Python(approach=lambda d: 0.0 * d))
