"""``afmkit spectroscopy fit --plot``: ``python3 -m afmkit._fit_plot --plot TABLE.csv OUT.png`` draws data vs fit from
the table the command wrote (afmkit.spectroscopy_fit.plot_table). A module of its own, which the package does not
import: run as ``-m afmkit.spectroscopy_fit``, that module (imported by the package first) would be executed twice
(runpy's RuntimeWarning on every plot)."""
import sys

from .spectroscopy_fit import _main

if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
