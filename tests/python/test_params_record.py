"""r.params records what a run used, and replays (issue 24 §2): a key whose default is another key records that
key's value, a default the command computes records the computed value, an alternative not given is left out."""
import math
from pathlib import Path

import numpy as np
import pytest

import afmkit
from afmkit import _afmkit
from afmkit import spectroscopy_fit, spectroscopy_reconstruct

# fast settings per command (each run takes well under a second)
FAST = {
    "impact": dict(mass1=1e-11, mass2=1.0, velocity=1e6, gap=2.0),
    "tapping hb": dict(points=50),
    "tapping orbit": dict(free_amplitude=10.0, separation=8.0),
    "tapping sweep": dict(free_amplitude=10.0, separation_min=7.0, separation_max=9.0, points=3, mode="instrument",
                          quiet=True),
    "tapping fm": dict(separation_min=7.0, separation_max=9.0, points=3, quiet=True),
    "tapping image": dict(pixels=8, lines=4, map_points=40, image_output="", quiet=True),
    "tapping modes": dict(separation_min=10.0, separation_max=12.0, points=2, settle_periods=20, lockin_periods=4, quiet=True),
    "control tf": dict(harmonics=3, points=20),
    "control roots": dict(harmonics=3),
    "control margin": dict(harmonics=3),
    "control chart": dict(harmonics=2, x_points=6, y_points=6),
    "control tune": dict(harmonics=2, coarse_points=6),
    "control simulate": dict(harmonics=2, periods=3, steps_per_period=64),
    "scan": dict(end_radius=2e-4, sample_resolution=64, image_resolution=32, sample_rate=5e3, spindle_frequency=50.0,
                 radial_speed=5e-4, harmonics=2),
    "demo": dict(points=5),
    "control export": dict(harmonics=3, sample_rate=1000.0),
    "spectroscopy fit": dict(spring_constant=40.0, resonance_frequency=300.0, quality_factor=100.0,
                             free_amplitude=10.0, parameters="phase_offset"),
    "spectroscopy reconstruct": dict(spring_constant=40.0, amplitude=2.0, round_trip="first_order",
                                     noise_realisations=0, law_output=""),
}
# commands that write files whatever the output keys say: into the test's folder
def _am_curve(d):
    """A small free-oscillation AM curve (no contact: a fit of the phase offset alone)."""
    path = d / "am.csv"
    path.write_text("distance (nm), amplitude (nm), phase (deg)\n40, 10, 90.1\n38, 10, 90.3\n36, 10, 89.9\n"
                    "34, 10, 90.2\n")
    return dict(file=str(path))


FILES = {"demo": lambda d: dict(output_dir=str(d / "demo")), "control export": lambda d: dict(output=str(d / "f.h")),
         "spectroscopy fit": _am_curve,
         "spectroscopy reconstruct": lambda d: dict(
             input=str(Path(__file__).resolve().parents[2] / "examples" / "configs" / "fm_curve_dmt.csv"))}
FUNCTIONS = {
    "impact": afmkit.impact, "tapping hb": afmkit.tapping.hb, "tapping orbit": afmkit.tapping.orbit,
    "tapping sweep": afmkit.tapping.sweep, "tapping fm": afmkit.tapping.fm, "control tf": afmkit.control.tf, "control roots": afmkit.control.roots,
    "tapping image": afmkit.tapping.image,
    "tapping modes": afmkit.tapping.modes,
    "control margin": afmkit.control.margin, "control chart": afmkit.control.chart,
    "control tune": afmkit.control.tune, "control simulate": afmkit.control.simulate, "scan": afmkit.scan,
    "demo": afmkit.demo, "control export": afmkit.control.export, "spectroscopy fit": spectroscopy_fit.run,
    "spectroscopy reconstruct": spectroscopy_reconstruct.reconstruct,
}
# a value for the followed key, inside its range, other than its default
NEW_VALUE = {"hamaker": 1e-19, "effective_modulus": 3.0, "plant_rate": 7.0, "delay": 0.05, "bandwidth": 5000.0,
             "resonance_frequency": 310.0}


def followers():
    """(command, key, followed key) for every parameter whose --help default reads "= <other key>"."""
    out = []
    for spec in _afmkit.commands():
        keys = {p["key"] for p in spec["params"]}
        for p in spec["params"]:
            text = p["default_text"]
            if text.startswith("= ") and text[2:] in keys:
                out.append((spec["path"], p["key"], text[2:]))
    return out


def test_the_followers_are_known_and_every_command_with_one_is_tested():
    found = followers()
    assert {(c, k) for c, k, _ in found if k == "departure_hamaker"} >= {("impact", "departure_hamaker"),
                                                                          ("tapping orbit", "departure_hamaker")}
    for command, key, source in found:
        assert command in FAST, f"{command}: {key} follows {source}; add fast settings to FAST"
        assert source in NEW_VALUE, f"{command}: {key} follows {source}; add a value to NEW_VALUE"


@pytest.mark.parametrize("command,key,source", followers())
def test_a_followed_default_is_recorded_as_the_value_used(command, key, source, tmp_path):
    kwargs = dict(FAST[command])
    kwargs.update(FILES.get(command, lambda d: {})(tmp_path))
    if (command.startswith("tapping") or command == "demo") and source in ("hamaker", "effective_modulus"):
        kwargs.update(units="physical", law="dmt")
    if command == "impact" and source in ("hamaker", "effective_modulus"):
        kwargs.update(law="dmt")
    if key in ("model_rate", "model_delay"):  # the Smith predictor's keys: recorded only with controller = smith
        if command in ("control simulate", "control export"):
            pytest.skip("the Smith predictor is neither simulated in the time domain nor exported: its keys never "
                        "apply there")
        kwargs.update(controller="smith")
    kwargs[source] = NEW_VALUE[source]
    r = FUNCTIONS[command](**kwargs)
    used = NEW_VALUE[source]
    expected = [used] if isinstance(r.params[key], list) else used  # delays = [delay]
    assert r.params[key] == expected, f"{command}: {key} recorded {r.params[key]}"
    # the record replays as it is (it lists only the keys of the unit system and law in use) and records the same
    again = FUNCTIONS[command](**r.params)
    assert again.params == r.params


def test_dmt_record_gives_the_same_law_and_replays():
    r = afmkit.impact(law="dmt", hamaker=1e-19, mass1=1e-11, mass2=1.0, velocity=1e6, gap=2.0)
    assert r.params["departure_hamaker"] == 1e-19
    assert "restitution" not in r.params
    again = afmkit.impact(**r.params)  # was: "departure_hamaker = 6.4e-20 must be >= hamaker"
    assert again.results["restitution"] == r.results["restitution"]
    # independently of the record: the run with both A_H given explicitly is the same impact
    explicit = afmkit.impact(law="dmt", hamaker=1e-19, departure_hamaker=1e-19, mass1=1e-11, mass2=1.0,
                             velocity=1e6, gap=2.0)
    assert explicit.results["restitution"] == r.results["restitution"]
    assert explicit.results["peak_force"] == r.results["peak_force"]


def test_an_alternative_is_recorded_only_when_used():
    r = afmkit.impact(restitution=0.5)
    assert r.params["restitution"] == 0.5 and "departure_stiffness" not in r.params
    assert afmkit.impact(**r.params).results["restitution"] == pytest.approx(
        r.results["restitution"], rel=1e-12)
    r = afmkit.impact(v1=1.0, v2=-2.0)
    assert "velocity" not in r.params and r.params["v1"] == 1.0
    assert afmkit.impact(**r.params).results["restitution"] == r.results["restitution"]


def test_computed_defaults_are_recorded_as_computed():
    r = afmkit.control.roots(harmonics=3)
    assert r.params["min_real"] == r.results["box"]["real_min"]
    assert r.params["max_imag"] == r.results["box"]["imag_max"]
    r = afmkit.control.tf(harmonics=3, plant_rate=7.0, points=20, controller="smith")
    assert r.params["gain"] == 7.0 and r.params["model_rate"] == 7.0
    assert "model_rate" not in afmkit.control.tf(harmonics=3, plant_rate=7.0, points=20).params  # not a Smith run
    r = afmkit.control.simulate(harmonics=2, periods=3, steps_per_period=64)
    phases = r.params["disturbance_phases"]
    assert len(phases) == len(r.params["disturbance_amplitudes"]) and phases[0] == 0.0
    assert all(0.0 <= p < 2 * math.pi for p in phases)
    again = afmkit.control.simulate(**r.params)  # the phases drawn, given explicitly: the same run
    assert again.params == r.params
    assert again.results["first_harmonic"]["abs"] == pytest.approx(r.results["first_harmonic"]["abs"], rel=1e-12)
    assert np.allclose(again["y"], r["y"], rtol=1e-12, atol=1e-15)


def test_signatures_show_none_for_a_default_that_is_not_a_fixed_value():
    """inspect.signature showed the declared default of a key that follows another (departure_hamaker = 6.4e-20,
    while the run uses hamaker's value; issue 24): such keys, and defaults the command chooses from other values,
    show None with the docstring saying what the default is; None given is the same as not given."""
    import inspect
    for command, fn in FUNCTIONS.items():
        spec = next(s for s in _afmkit.commands() if s["path"] == command)
        sig = inspect.signature(fn).parameters
        for p in spec["params"]:
            if p["key"] == "json":
                continue
            shown = sig[p["key"]].default
            if p["follows"]:
                assert shown is None, (command, p["key"])
                assert f"{p['key']} (" in fn.__doc__ and f"defaults to {p['follows']}" in fn.__doc__
            elif p["default_text"]:
                assert shown is None, (command, p["key"])
            else:
                assert shown == p["default"], (command, p["key"])
    for command, key, source in followers():  # declared (follows) or chosen by the command ("= plant_rate")
        if command in FUNCTIONS:
            assert inspect.signature(FUNCTIONS[command]).parameters[key].default is None
            assert f"defaults to {source} (its value is used" in FUNCTIONS[command].__doc__, (command, key)
    sig = inspect.signature(afmkit.tapping.hb).parameters
    assert sig["departure_hamaker"].default is None and sig["hamaker"].default == 6.4e-20
    # the default None stands for the value recorded: departure_hamaker = hamaker's value, as r.params records it
    r = afmkit.tapping.hb(units="physical", law="dmt", hamaker=1e-19, departure_hamaker=None, points=50)
    assert r.params["departure_hamaker"] == 1e-19


def test_a_fixed_signature_default_is_the_value_recorded():
    import inspect
    for command in ("tapping hb", "control tf", "impact", "control simulate"):
        r = FUNCTIONS[command](**FAST[command])
        for key, p in inspect.signature(FUNCTIONS[command]).parameters.items():
            if key in FAST[command] or p.default is None or key not in r.params:
                continue
            assert r.params[key] == p.default, (command, key, r.params[key], p.default)


def test_a_call_leaves_the_next_calls_defaults_alone():
    # the module declares a command's parameters once and copies them per call (speed, bench/command_layer.py): a
    # value given, or computed and recorded by the run, must not become the default of the next call
    spec = next(s for s in _afmkit.commands() if s["path"] == "tapping hb")
    declared = {p["key"]: p["default"] for p in spec["params"]}
    other = declared["quality_factor"] * 2 + 1
    kw = FAST["tapping hb"]
    given = afmkit.tapping.hb(**kw, quality_factor=other)
    default = afmkit.tapping.hb(**kw)
    assert given.params["quality_factor"] == other
    assert default.params["quality_factor"] == declared["quality_factor"]


def test_a_reused_parameter_set_starts_from_the_declaration(tmp_path):
    # the module reuses a command's parameter sets, their values reset per call (ParamSet::reset_values): a config
    # file, a call refused half-way through its keywords or calls running at once must not reach another call
    spec = next(s for s in _afmkit.commands() if s["path"] == "tapping orbit")
    declared = {p["key"]: p["default"] for p in spec["params"]}
    kw = dict(quality_factor=2.0, max_period_multiple=1)  # about a millisecond per call
    config = tmp_path / "orbit.toml"
    config.write_text("separation = 6.5\nfrequency_ratio = 1.01\n")
    for calls in range(3):  # one call after another: each takes the set the previous one gave back
        assert afmkit.tapping.orbit(**kw, config=config).params["frequency_ratio"] == 1.01
        with pytest.raises(afmkit.InvalidParameter, match="drive_amplitude"):  # after separation was applied
            afmkit.tapping.orbit(**kw, separation=3.5, drive_amplitude=-1.0)
        assert afmkit.tapping.orbit(**kw, config=config).params["separation"] == 6.5
        assert afmkit.tapping.orbit(**kw, separation=3.0, drive_amplitude=0.3).params["separation"] == 3.0
        r = afmkit.tapping.orbit(**kw)
        assert r.params["separation"] == declared["separation"] not in (3.0, 3.5, 6.5)
        assert r.params["frequency_ratio"] == declared["frequency_ratio"] != 1.01
        assert r.params["drive_amplitude"] == declared["drive_amplitude"] != 0.3

    from concurrent.futures import ThreadPoolExecutor  # the computation runs without the GIL: sets in use at once
    separations = [4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 4.5, 5.5]
    with ThreadPoolExecutor(4) as pool:
        runs = list(pool.map(lambda s: afmkit.tapping.orbit(**kw, separation=s), separations))
    assert [r.params["separation"] for r in runs] == separations
    assert [r.results["separation"] for r in runs] == separations  # normalised units: as given
