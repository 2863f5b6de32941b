"""Control from Python (issue 26 §4): SI keywords given instead of Ω and T give the same results bit for bit and are
never guessed (both forms refused); controller objects that every command takes; simulate driven by the user's
samples, checked against a discrete simulation of the loop written here; state-space matrices that reproduce tf's
response through C (jωI − A)⁻¹ B + D; python-control interop where it is installed. Small problems: well under a
second each."""
import json
import math
import os
import subprocess

import numpy as np
import pytest

import afmkit
import afmkit.control as ctl

CLI = os.environ.get("AFMKIT_CLI", "")

F_HZ = 50.0
OMEGA = 2.0 * math.pi * F_HZ  # what rotation_frequency_hz = 50 means (rad/s), computed as afmkit does
PERIOD = 2.0 * math.pi / OMEGA


def _seconds(in_periods):
    """The SI value of a delay given in T, checked to convert back exactly (so that both runs get the same double)."""
    s = in_periods * PERIOD
    assert s / PERIOD == in_periods
    return s


def _rad_per_s(in_omega):
    r = in_omega * OMEGA
    assert r / OMEGA == in_omega
    return r


def _same(a, b):
    assert a.columns == b.columns
    for c in a.columns:
        x, y = np.asarray(a[c]), np.asarray(b[c])
        assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), c
    # the summaries, NaN included (json writes every double exactly)
    assert json.dumps(a.results, sort_keys=True) == json.dumps(b.results, sort_keys=True)


# ---------------------------------------------------------------- 1. SI inputs, identical results
NORMALISED = dict(rotation_frequency=OMEGA, harmonics=4, alpha=0.125, beta=-0.0625, plant_rate=16.0, delay=0.125)
SI = dict(rotation_frequency_hz=F_HZ, harmonics=4, alpha_rad_per_s=_rad_per_s(0.125),
          beta_rad_per_s=_rad_per_s(-0.0625), plant_rate_rad_per_s=_rad_per_s(16.0), delay_seconds=_seconds(0.125))


def test_si_and_rotation_units_give_identical_tf():
    _same(ctl.tf(points=30, frequency_min=0.5, frequency_max=4.0, system="loop", **NORMALISED),
          ctl.tf(points=30, frequency_min_rad_per_s=_rad_per_s(0.5), frequency_max_rad_per_s=_rad_per_s(4.0),
                 system="loop", **SI))
    # Hz: f = omega/(2 pi), so 2 pi f / Omega must give the same double
    f_lo, f_hi = 0.5 * F_HZ, 4.0 * F_HZ
    assert 2 * math.pi * f_lo / OMEGA == 0.5 and 2 * math.pi * f_hi / OMEGA == 4.0
    _same(ctl.tf(points=30, frequency_min=0.5, frequency_max=4.0, **NORMALISED),
          ctl.tf(points=30, frequency_min_hz=f_lo, frequency_max_hz=f_hi, **SI))


def test_si_and_rotation_units_give_identical_margin_chart_simulate():
    _same(ctl.margin(**NORMALISED), ctl.margin(**SI))
    _same(ctl.margin(reference_delay=0.0625, **NORMALISED), ctl.margin(reference_delay_seconds=_seconds(0.0625), **SI))
    _same(ctl.chart(x_points=4, y_points=3, delays=[0.125, 0.25], progress=False, **NORMALISED),
          ctl.chart(x_points=4, y_points=3, delays_seconds=[_seconds(0.125), _seconds(0.25)], progress=False, **SI))
    _same(ctl.simulate(periods=3, steps_per_period=64, record_every=4, **NORMALISED),
          ctl.simulate(periods=3, steps_per_period=64, record_every=4, **SI))


def test_si_run_is_recorded_in_its_own_keys_and_replays():
    r = ctl.margin(**SI)
    assert "delay_seconds" in r.params and "delay" not in r.params
    assert "rotation_frequency_hz" in r.params and "rotation_frequency" not in r.params
    _same(r, ctl.margin(**r.params))


def test_tf_frequency_axis_in_the_unit_asked():
    omega = ctl.tf(points=5, frequency_unit="rad/s", **SI)
    hz = ctl.tf(points=5, frequency_unit="Hz", **SI)
    rot = ctl.tf(points=5, **SI)
    assert omega.units["frequency"] == "rad/s" and hz.units["frequency"] == "Hz" and rot.units["frequency"] == "Omega"
    np.testing.assert_allclose(omega["frequency"], rot["frequency"] * OMEGA, rtol=1e-14)
    np.testing.assert_allclose(hz["frequency"], rot["frequency"] * F_HZ, rtol=1e-14)
    # the controller's response: units of Omega (C/Omega) against 1/s
    np.testing.assert_allclose(omega["real"], rot["real"] * OMEGA, rtol=1e-14, atol=1e-12)


@pytest.mark.parametrize("given", [dict(delay=0.1, delay_seconds=0.002), dict(alpha=0.1, alpha_rad_per_s=30.0),
                                   dict(rotation_frequency=3.0, rotation_frequency_hz=50.0),
                                   dict(frequency_max=3.0, frequency_max_hz=50.0)])
def test_both_forms_of_a_quantity_are_refused_naming_both(given):
    a, b = list(given)
    with pytest.raises(ValueError, match=f"{a} and {b} were both given"):
        ctl.tf(points=3, **given)


def test_cli_refuses_both_forms_with_exit_2_and_nothing_written(tmp_path):
    if not CLI:
        pytest.skip("AFMKIT_CLI not set")
    out = tmp_path / "m.csv"
    p = subprocess.run([CLI, "control", "margin", "--delay", "0.1", "--delay-seconds", "0.002", "--output", str(out)],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "delay and delay_seconds were both given" in p.stderr
    assert not out.exists()


# ---------------------------------------------------------------- 2. controller objects
def test_controller_object_is_what_its_keywords_are():
    d = ctl.Controller(harmonics=5, alpha=0.2, beta=-0.05, gain=18.0)
    assert d.params == dict(harmonics=5, alpha=0.2, beta=-0.05, gain=18.0)
    _same(ctl.margin(controller=d), ctl.margin(**d.params))
    _same(d.tf(points=7), ctl.tf(points=7, **d.params))
    # the call's keywords take precedence, in any of their units
    _same(d.margin(delay_seconds=_seconds(0.125), rotation_frequency_hz=F_HZ),
          ctl.margin(harmonics=5, alpha=0.2, beta=-0.05, gain=18.0, delay=0.125, rotation_frequency=OMEGA))
    with pytest.raises(TypeError, match="unexpected keyword"):
        ctl.Controller(points=3)
    with pytest.raises(ValueError, match="harmonics"):
        ctl.Controller(harmonics=0)


def test_tune_returns_a_design_every_command_takes():
    r = ctl.tune(harmonics=3, coarse_points=3, max_evaluations=4, delay_points=2, gain_points=1, progress=False)
    d = r.controller
    assert isinstance(d, ctl.Controller)
    opt = r.results.optimum
    assert d.params["alpha"] == opt["alpha"] and d.params["beta"] == opt["beta"]
    expected = ctl.margin(harmonics=3, alpha=opt["alpha"], beta=opt["beta"])
    _same(ctl.margin(controller=d), expected)
    _same(ctl.margin(controller=r), expected)
    _same(d.simulate(periods=2, steps_per_period=32), ctl.simulate(periods=2, steps_per_period=32, harmonics=3,
                                                                     alpha=opt["alpha"], beta=opt["beta"]))


def test_export_takes_a_design(tmp_path):
    d = ctl.Controller(harmonics=3, alpha=0.1, beta=-0.1, rotation_frequency_hz=F_HZ)
    d.export(sample_rate=10000.0, test_vectors=20, output=str(tmp_path / "design.h"))
    ctl.export(harmonics=3, alpha=0.1, beta=-0.1, rotation_frequency=OMEGA, sample_rate=10000.0, test_vectors=20,
               output=str(tmp_path / "keywords.h"))
    assert (tmp_path / "design.h").read_bytes() == (tmp_path / "keywords.h").read_bytes()


# ---------------------------------------------------------------- 3. simulate driven by the user's samples
def test_sampled_signal_gives_the_fourier_path():
    s = 45
    theta = 2 * math.pi * np.arange(2 * s) / s  # two periods
    f = 0.2 + np.sin(theta) + 0.3 * np.sin(3 * theta + 1.0) + 0.05 * np.sin(7 * theta - 0.4)
    common = dict(harmonics=4, periods=8, steps_per_period=90, record_every=1, plant="first_order")
    fourier = ctl.simulate(disturbance_offset=0.2, disturbance_amplitudes=[1, 0, 0.3, 0, 0, 0, 0.05],
                           disturbance_phases=[0, 0, 1.0, 0, 0, 0, -0.4], **common)
    sampled = ctl.simulate(signal=f, signal_sample_rate=s / (2 * math.pi), **common)
    for c in ("y", "u", "m", "target"):
        np.testing.assert_allclose(sampled[c], fourier[c], rtol=0, atol=1e-12)
    assert sampled.results.signal.periods == 2 and sampled.results.signal.samples_per_period == s
    assert sampled.results.signal.non_periodic_rms < 1e-14  # the two periods are the same (to the rounding of sin)


def test_sampled_signal_against_a_discrete_simulation_written_here():
    """Static plant y = f + u/gamma (eq. 3), single oscillator (eqs. 5-6) stepped exactly for the held measurement
    (zero-order hold), m_n = y_{n-d}; f = the raw samples (odd count: no Nyquist term), not its Fourier series."""
    m_steps, d, periods = 101, 10, 6
    rng = np.random.default_rng(7)
    f = rng.normal(size=m_steps)
    omega, a, b, gain, gamma = 1.0, 0.5, 0.1, 20.0, 20.0
    h = 2 * math.pi / omega / m_steps
    r = ctl.simulate(controller="single", a=a, b=b, gain=gain, plant_rate=gamma, delay=d / m_steps,
                     signal=f, signal_step=1.0 / m_steps, method="zoh", periods=periods,
                     steps_per_period=m_steps, record_every=1)
    # exact discretisation of x' = -omega z + a m, z' = omega x + b m for m held over a step
    c_, s_ = math.cos(omega * h), math.sin(omega * h)
    phi = np.array([[c_, -s_], [s_, c_]])
    a_mat = np.array([[0.0, -omega], [omega, 0.0]])
    gam = np.linalg.solve(a_mat, (phi - np.eye(2)) @ np.array([a, b]))
    state = np.zeros(2)
    y_hist = {j: f[j % m_steps] for j in range(-d, 0)}  # the plant ran uncontrolled before t = 0
    ys = []
    for n in range(periods * m_steps):
        u = -gain * state[0]
        y = f[n % m_steps] + u / gamma
        y_hist[n] = y
        state = phi @ state + gam * y_hist[n - d]
        ys.append(y)
    np.testing.assert_allclose(r["y"], ys, rtol=0, atol=1e-9 * np.max(np.abs(ys)))


def test_signal_from_a_text_file_column_is_the_array(tmp_path):
    f = np.random.default_rng(3).normal(size=9)
    path = tmp_path / "measured.csv"
    path.write_text("time (s), height (nm)\n" + "".join(f"{i / 450.0!r}, {x!r}\n" for i, x in enumerate(f)))
    common = dict(harmonics=3, periods=4, steps_per_period=40, rotation_frequency_hz=F_HZ, signal_sample_rate=450.0)
    from_file = ctl.simulate(signal_file=str(path), signal_column="height", **common)
    _same(from_file, ctl.simulate(signal=f, **common))
    _same(from_file, ctl.simulate(signal_file=str(path), signal_column="2", **common))
    assert from_file.params["signal_file"] == str(path) and "signal" not in from_file.params


def test_signal_mistakes_are_named():
    with pytest.raises(ValueError, match="without its sampling"):
        ctl.simulate(signal=[0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="whole rotation periods"):
        ctl.simulate(signal=[0.0, 1.0, 0.0, 2.0, 1.0], signal_step=1 / 3)
    with pytest.raises(ValueError, match="whole number of samples per period"):
        ctl.simulate(signal=[0.0, 1.0, 0.0], signal_step=0.3)
    with pytest.raises(ValueError, match="signal and disturbance_amplitudes were both given"):
        ctl.simulate(signal=[0.0, 1.0, 0.0], signal_step=1 / 3, disturbance_amplitudes=[1.0])
    with pytest.raises(ValueError, match="signal_step_seconds and signal_sample_rate were both given"):
        ctl.simulate(signal=[0.0, 1.0, 0.0], signal_step_seconds=1.0, signal_sample_rate=1.0)


# ---------------------------------------------------------------- 4. state space and frequency-response data
@pytest.mark.parametrize("design", [dict(harmonics=4, alpha=0.1, beta=-0.1, rejected=[1, 3]),
                                    dict(controller="single", a=0.5, b=0.2, gain=12.0)])
def test_state_space_reproduces_the_frequency_response(design):
    d = ctl.Controller(rotation_frequency_hz=F_HZ, **design)
    A, B, C, D = d.state_space()
    omega, response = d.frequency_response(frequency_min_hz=1.0, frequency_max_hz=400.0, points=40)
    by_matrices = np.array([(C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B) + D)[0, 0] for w in omega])
    np.testing.assert_allclose(by_matrices, response, rtol=1e-9, atol=1e-9 * np.max(np.abs(response)))
    # the plant: delay-free matrices times e^{-i omega tau}
    Ap, Bp, Cp, Dp = d.state_space("plant", plant="first_order")
    om, plant = d.frequency_response("plant", plant="first_order", frequency_min_hz=1.0, frequency_max_hz=400.0,
                                     points=20)
    tau = d.settings_si["delay"]
    p0 = np.array([(Cp @ np.linalg.solve(1j * w * np.eye(Ap.shape[0]) - Ap, Bp) + Dp)[0, 0] for w in om])
    np.testing.assert_allclose(p0 * np.exp(-1j * om * tau), plant, rtol=1e-12)


def test_no_state_space_for_the_infinite_bank():
    with pytest.raises(ValueError, match="no finite state-space realisation"):
        ctl.Controller(controller="infinite").state_space()


def test_python_control_accepts_the_data():
    ct = pytest.importorskip("control")
    d = ctl.Controller(harmonics=3, rotation_frequency_hz=F_HZ)
    sys = d.to_python_control()
    omega, response = d.frequency_response(points=15)
    np.testing.assert_allclose(np.squeeze(sys(1j * omega)), response, rtol=1e-9)
    frd = ct.frd(response, omega)
    np.testing.assert_allclose(np.squeeze(frd.fresp), response)
