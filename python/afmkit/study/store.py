"""Where a study's results live: a Zarr store (v2, uncompressed) that xarray opens as a Dataset.

Layout: one coordinate array per axis (its values, attribute `units`), one float64 array per output over all axes
(NaN where not computed or undefined), chunked exactly as the study is cut into work; `chunk_done` (one int8 per
chunk, written after the chunk's outputs) and `chunk_failed` (points that failed numerically per chunk). The
root's attributes hold the study's definition and fingerprint: a store is only ever filled by the study that
created it.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from .definition import Study, StudyError

FORMAT = 1


def chunk_shape(shape: tuple, target_points: int) -> tuple:
    """Chunk shape of about `target_points` points: whole trailing axes first, then part of the next one."""
    out = [1] * len(shape)
    remaining = max(1, int(target_points))
    for i in reversed(range(len(shape))):
        take = min(shape[i], remaining)
        out[i] = take
        if take < shape[i]:
            break
        remaining //= take
    return tuple(out)


def chunk_grid(shape: tuple, chunks: tuple) -> tuple:
    return tuple(math.ceil(n / c) for n, c in zip(shape, chunks))


def chunk_slices(shape: tuple, chunks: tuple, index: int) -> tuple:
    """The slices of chunk `index` (C order over the chunk grid)."""
    position = np.unravel_index(index, chunk_grid(shape, chunks))
    return tuple(slice(p * c, min((p + 1) * c, n)) for p, c, n in zip(position, chunks, shape))


def output_names(outputs) -> list:
    """A variable name per output selector: "max(amplitude | stable)" -> "max_amplitude_stable"."""
    names = []
    for o in outputs:
        name = "".join(ch if ch.isalnum() else "_" for ch in o.strip())
        name = "_".join(p for p in name.split("_") if p)
        names.append(name or "output")
    if len(set(names)) != len(names):
        raise StudyError("outputs", f"outputs: two outputs map to the same name ({names})")
    return names


def create(path: Path, study: Study, chunks: tuple, output_units: list, version: str) -> None:
    """Creates the store at `path` (complete or not at all: built beside it, then renamed)."""
    import zarr

    path = Path(path)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.tmp-", dir=path.parent))
    try:
        root = zarr.open_group(str(tmp), mode="w")
        units = study.units()
        dims = [a.name for a in study.axes]
        for a in study.axes:
            # no fill value: xarray would read a coordinate equal to it (0.0 by default) as missing
            c = root.create_dataset(a.name, data=np.asarray(a.values, dtype="f8"), compressor=None, fill_value=None)
            c.attrs.update({"_ARRAY_DIMENSIONS": [a.name], "units": units[a.name]})
        for name, selector, unit in zip(output_names(study.outputs), study.outputs, output_units):
            v = root.create_dataset(name, shape=study.shape, chunks=chunks, dtype="f8", fill_value=np.nan,
                                    compressor=None)
            v.attrs.update({"_ARRAY_DIMENSIONS": dims, "units": unit, "selector": selector,
                            "description": f"{selector} of afmkit {study.command} at each point"})
        n = int(np.prod(chunk_grid(study.shape, chunks)))
        for name, dtype, what in (("chunk_done", "i1", "1 when the chunk's outputs are written"),
                                  ("chunk_failed", "i4", "points of the chunk whose computation failed numerically")):
            a = root.create_dataset(name, shape=(n,), chunks=(1,), dtype=dtype, fill_value=0, compressor=None)
            a.attrs.update({"_ARRAY_DIMENSIONS": ["chunk"], "units": "count", "description": what})
        root.attrs.update({"afmkit_study_format": FORMAT, "study_name": study.name,
                           "study_fingerprint": study.fingerprint(),
                           "study_definition": json.dumps(study.definition(), sort_keys=True),
                           "computation": study.computation, "command": f"afmkit {study.command}",
                           "afmkit_version": version})
        zarr.consolidate_metadata(str(tmp))
        os.replace(tmp, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def open_existing(path: Path, study: Study):
    """The store at `path` if it was written by `study` (else StudyError naming `store`); its chunk shape."""
    import zarr

    try:
        root = zarr.open_group(str(path), mode="r+")
        attrs = dict(root.attrs)
    except Exception as e:  # noqa: BLE001 - any unreadable store is refused the same way
        # Zarr's own text is not shown: some of its messages are unformatted templates ("… %r")
        why = e.strerror if isinstance(e, OSError) and e.strerror else type(e).__name__
        raise StudyError("store", f"store '{path}' exists but is not an afmkit study store ({why}): remove it or "
                                  f"choose another") from None
    if attrs.get("afmkit_study_format") != FORMAT or "study_fingerprint" not in attrs:
        raise StudyError("store", f"store '{path}' exists but is not an afmkit study store (remove it or choose "
                                  f"another)")
    if attrs["study_fingerprint"] != study.fingerprint():
        theirs = json.loads(attrs.get("study_definition", "{}"))
        mine = study.definition()
        differing = [k for k in mine if theirs.get(k) != mine[k]]
        raise StudyError("store", f"store '{path}' holds the results of a different study (its "
                                  f"{', '.join(differing) or 'definition'} differ): refused, results are never "
                                  f"mixed; choose another store or remove it")
    name = output_names(study.outputs)[0]
    return root, tuple(root[name].chunks)
