"""Parameter studies: a grid of afmkit computations, run serially, on all cores or on a Dask cluster, with the
results as an xarray Dataset stored in Zarr (docs/study.md).

    from afmkit.study import Study, run
    s = Study.make("tapping.orbit", axes={"separation": {"start": 7, "stop": 12, "points": 51},
                                          "frequency_ratio": [0.99, 1.0, 1.005]},
                   outputs=["max(amplitude | stable)", "count(amplitude | stable)"],
                   parameters={"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0})
    ds = run(s, "out/jumps.zarr")                  # local workers, one per core (when the study is long enough)
    ds = run(s, "out/jumps.zarr", scheduler="serial")
    ds = run(s, "out/jumps.zarr", scheduler="tcp://head:8786")
"""
from .definition import COMPUTATIONS, Axis, Study, StudyError
from .run import StudyFailure, run

__all__ = ["Study", "Axis", "StudyError", "StudyFailure", "run", "COMPUTATIONS"]
