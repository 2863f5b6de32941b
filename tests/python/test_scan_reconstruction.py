"""scan's two topography reconstructions (docs/scan.md#reconstruction) from Python: both images drawn, the error
budget in the results, the assumed plant rate as a keyword."""
import numpy as np

import afmkit


def _small(tmp_path, **kw):
    return afmkit.scan(sample="rough", sample_resolution=64, end_radius=5e-4, radial_speed=1e-3, sample_rate=5000,
                       image_resolution=16, image_output=str(tmp_path / "s"), output="", **kw)


def test_scan_reconstruction_both_images_and_the_budget(tmp_path):
    r = _small(tmp_path)
    assert r.results.reconstruction == "inverse"
    # an ideal instrument: the inverse adds nothing to the imaging floor; the lagged one carries the lag
    assert r.results.error_budget["reconstruction"] < 1e-9 * r.results.sample_rms_height
    assert r.results.lagged_rms_error > 3 * r.results.inverse_rms_error
    chosen = r.plot(channel="topography").get_images()[0].get_array()
    same = r.plot(channel="topography_inverse").get_images()[0].get_array()  # the chosen one, by its name
    lagged = r.plot(channel="topography_lagged").get_images()[0].get_array()
    np.testing.assert_array_equal(np.ma.filled(chosen, np.nan), np.ma.filled(same, np.nan))
    assert not np.allclose(np.ma.filled(chosen, 0.0), np.ma.filled(lagged, 0.0))


def test_scan_reconstruction_assumed_plant_rate_costs_the_first_order_term(tmp_path):
    r = _small(tmp_path, control="off", tilt_angle=0.0, reconstruction_bandwidth=1.05 * 2 * np.pi * 1000)
    b = r.results.error_budget
    assert abs(b["plant_mismatch"] - 0.05) < 1e-12
    # |γ/γ̂ − 1| × the lagged error, against the measured reconstruction error
    assert abs(b["plant"] / b["reconstruction"] - 1) < 0.3
    assert r.params["reconstruction_bandwidth"] == 1.05 * 2 * np.pi * 1000
