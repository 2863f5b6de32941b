"""Contact-aware hysteresis from Python (docs/force-laws.md#hysteresis): a table law is contact-aware by default;
hysteresis="velocity" gives the seed's rule; the same numbers as the command line."""
import json
import os
import subprocess

import pytest

import afmkit

SOURCE = os.environ.get("AFMKIT_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CURVE = os.path.join(SOURCE, "examples", "force_curves", "neck_pulloff.csv")
SOFT = dict(units="physical", law="table", force_curve=CURVE, spring_constant=1.1841, resonance_frequency=23.251,
            quality_factor=139.13, free_amplitude=20.0, separation=40.0)


def test_a_tip_that_never_touches_dissipates_nothing_unless_velocity_switching_is_asked():
    aware = afmkit.tapping.orbit(**SOFT)
    seed = afmkit.tapping.orbit(hysteresis="velocity", **SOFT)
    assert aware.params["hysteresis"] == "law"
    assert len(aware.table["amplitude"]) == 1 and len(seed.table["amplitude"]) == 1
    # 20 nm above the drag-only range: the free orbit (A/A0 = 1) without loss; the seed's rule loses 0.74 aJ/cycle
    assert aware.table["amplitude"][0] == pytest.approx(20.0, rel=1e-5)
    assert abs(aware.table["contact_dissipation"][0]) <= 1e-10 * aware.table["viscous_dissipation"][0]
    assert seed.table["contact_dissipation"][0] > 0.05 * seed.table["viscous_dissipation"][0]
    assert seed.table["amplitude"][0] < 19.0
    # the same numbers as the command line
    args = [f"--{k.replace('_', '-')}={v}" for k, v in SOFT.items()]
    r = subprocess.run([os.environ["AFMKIT_CLI"], "tapping", "orbit", *args, "--hysteresis", "velocity", "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["orbits"][0]["amplitude"] == pytest.approx(seed.table["amplitude"][0], rel=1e-12)


def test_contact_hysteresis_is_refused_for_the_seeds_laws():
    with pytest.raises(afmkit.InvalidParameter, match="hysteresis = contact applies only to law = table"):
        afmkit.tapping.orbit(units="physical", law="dmt", hysteresis="contact")
