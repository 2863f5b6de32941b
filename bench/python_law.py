"""Benchmark of force laws written in Python (docs/force-laws.md#python; issue 26: a Python law costs <= 20x the same
built-in law per orbit).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_law.py [--repeat 5]

Runs `tapping orbit` with the built-in DMT, Hertz and Kelvin–Voigt laws and with the same laws written in Python
(afmkit.laws.Python),
interleaved, and prints the fastest wall time of each, the ratio Python / built-in per orbit (the target: <= 20),
the one-time cost of tabulating the callables, the cost per law evaluation inside the tabulated domain, and the cost
of a call into Python (what every evaluation would cost without the tabulation; the law beyond its domain).
Exit status 1 when a ratio exceeds 20. Run it on an otherwise idle machine.
"""
import argparse
import sys
import time

import numpy as np

import afmkit
from afmkit import laws

E, R, A, A0 = 1e9, 10e-9, 1e-19, 0.165e-9  # SI: E* [Pa], R [m], A_H [J], a0 [m]
CANTILEVER = dict(spring_constant=40.0, resonance_frequency=300.0, quality_factor=100.0, free_amplitude=10.0)


def dmt(d):
    return -A * R / (6.0 * np.maximum(d, A0) ** 2) + 4.0 / 3.0 * E * np.sqrt(R) * np.clip(A0 - d, 0.0, None) ** 1.5


def damping(d):  # Kelvin–Voigt: η √(R (a0 − d)) in contact, η = 50 Pa s
    return 50.0 * np.sqrt(R * np.clip(A0 - d, 0.0, None))


def hertz(d):
    return 4.0 / 3.0 * E * np.sqrt(R) * np.clip(-d, 0.0, None) ** 1.5


def fastest(f, repeat):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    t = time.perf_counter()
    py_dmt = laws.Python(dmt, switching_gaps=[A0], name="dmt")
    tabulate = time.perf_counter() - t
    cases = {
        "dmt": (laws.DMT(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19), py_dmt, dict(separation=8.0)),
        "hertz": (laws.Hertz(effective_modulus=1.0, tip_radius=10.0), laws.Python(hertz, switching_gaps=[0.0]),
                  dict(separation=8.0)),
        "kelvin_voigt": (laws.KelvinVoigt(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19, viscosity=50.0),
                         laws.Python(dmt, damping=damping, switching_gaps=[A0]), dict(separation=8.0)),
    }
    print(f"tabulating the DMT callable: {tabulate * 1e3:.2f} ms once ({py_dmt.tabulation['approach']['pieces']} Chebyshev "
          "pieces of degree 16)")
    failed = False
    for name, (builtin, python, kw) in cases.items():
        times = {"built-in": np.inf, "python": np.inf}
        for _ in range(args.repeat):  # interleaved: drifts of the machine hit both alike
            for label, law in (("built-in", builtin), ("python", python)):
                times[label] = min(times[label], fastest(lambda: afmkit.tapping.orbit(law=law, **kw, **CANTILEVER), 1))
        a = afmkit.tapping.orbit(law=builtin, **kw, **CANTILEVER)
        b = afmkit.tapping.orbit(law=python, **kw, **CANTILEVER)
        same = len(a) == len(b) and np.allclose(a["amplitude"], b["amplitude"], rtol=1e-7)
        ratio = times["python"] / times["built-in"]
        failed |= ratio > 20.0 or not same
        print(f"tapping orbit, {name}: built-in {times['built-in'] * 1e3:.1f} ms, Python law {times['python'] * 1e3:.1f} "
              f"ms per orbit search ({len(a)} orbits): ratio {ratio:.2f} (target <= 20; same orbits: {same})")

    d = np.linspace(-2e-9, 20e-9, 200_000)
    builtin = laws.DMT(effective_modulus=1.0, tip_radius=10.0, hamaker=1e-19)
    tb = fastest(lambda: builtin.force(d), args.repeat) / d.size
    tp = fastest(lambda: py_dmt.force(d), args.repeat) / d.size
    beyond = laws.Python(dmt, switching_gaps=[A0], domain=(-1e-9, 0.0))  # every d > 0 calls Python
    few = np.linspace(1e-9, 20e-9, 2000)
    tc = fastest(lambda: beyond.force(few), args.repeat) / few.size
    print(f"law evaluation (force(), both branches and damping, SI conversion): built-in {tb * 1e9:.0f} ns, Python "
          f"law tabulated {tp * 1e9:.0f} ns, calling the callable per point {tc * 1e6:.2f} us (x{tc / tb:.0f})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
