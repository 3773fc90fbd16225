"""Results files: the per-trial arrays of a run streamed to a NetCDF-4 file block by block.

``plansim run --out FILE.nc`` must not hold 10⁶ trials × 39 parameters × 3 arrays in memory (0.94 GB)
to write them, as xarray's NetCDF-3 writer (scipy) does until the file is closed. :class:`ResultsFile`
writes the Dataset's coordinates and attributes first, through xarray (``engine="h5netcdf"``, the
``trial`` dimension unlimited, chunked in blocks of trials), then fills ``trial``, ``truth``,
``estimate`` and ``error`` a block at a time through h5netcdf. What comes out is the Dataset
:func:`plansim.runner.run` returns, read back by ``xarray.open_dataset(FILE)``.

The file is written whole or not at all: everything goes to a hidden temporary file beside the
target (``.NAME.XXXX.part``) that :meth:`ResultsFile.commit` renames onto the target; on any
exception (KeyboardInterrupt included) or without a commit, the temporary file is removed.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr

#: the per-trial variables of a results file, over (trial, parameter)
RESULT_VARIABLES = ("truth", "estimate", "error")
#: trials per HDF5 chunk of the per-trial variables (39 × 8 bytes each: 1.2 MiB per chunk)
CHUNK_TRIALS = 4096
#: bytes of file per trial beyond the three arrays' 936 (the trial coordinate; HDF5 bookkeeping is per chunk)
_FILE_BYTES_PER_TRIAL = 8


def results_file_bytes(trials: int, parameters: int = 39) -> int:
    """Size of a results file for *trials* trials, bytes (the three float64 arrays, the trial coordinate and
    a margin of 1 MiB for the coordinates, attributes and HDF5 headers)."""
    return trials * (len(RESULT_VARIABLES) * parameters * 8 + _FILE_BYTES_PER_TRIAL) + 2**20


class ResultsFile:
    """A results file written block by block, committed whole or not at all.

    Parameters
    ----------
    path : str or os.PathLike
        The target, ``*.nc``; its folder must exist.

    Examples
    --------
    >>> with ResultsFile("r.nc") as out:                       # doctest: +SKIP
    ...     out.start(template, trials)                         # coordinates and attributes
    ...     out.write(0, truth=t, estimate=e, error=e - t)      # trials 0 … len(t) − 1
    ...     out.commit()                                        # renamed onto r.nc

    Leaving the ``with`` block without :meth:`commit`, or by an exception, removes the temporary file
    and leaves the target as it was.
    """

    def __init__(self, path: str | os.PathLike):
        target = Path(path)
        folder = target.parent if str(target.parent) else Path(".")
        if not folder.is_dir():
            raise ValueError(f"output {str(target)!r}: the folder {str(folder)!r} does not exist")
        self.path = target
        fd, self.temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=folder)
        os.close(fd)
        self._file = None
        self._trials = 0
        self.committed = False

    def check_space(self, trials: int) -> None:
        """ValueError if the target's folder has less free space than the file will need."""
        need = results_file_bytes(trials)
        free = shutil.disk_usage(os.path.dirname(self.temporary) or ".").free
        if need > free:
            raise ValueError(f"trials = {trials}: the results file {str(self.path)!r} needs about "
                             f"{need / 1e9:.3g} GB, but its folder has {free / 1e9:.3g} GB free")

    def start(self, template: xr.Dataset, trials: int) -> None:
        """Write *template*'s coordinates, attributes and the (empty) per-trial variables, sized for *trials*.

        *template* is a results Dataset with zero trials (:func:`plansim.runner.results_dataset` of empty
        arrays) whose ``attrs`` already describe the whole run.
        """
        import h5netcdf

        if self._file is not None:
            raise ValueError(f"results file {str(self.path)!r}: already started")
        chunk = max(1, min(CHUNK_TRIALS, trials))
        encoding = {name: {"chunksizes": (chunk, template.sizes["parameter"])} for name in RESULT_VARIABLES}
        encoding["trial"] = {"chunksizes": (chunk,)}
        template.to_netcdf(self.temporary, engine="h5netcdf", unlimited_dims=["trial"], encoding=encoding)
        self._file = h5netcdf.File(self.temporary, "a")
        self._file.resize_dimension("trial", trials)
        self._trials = trials

    def write(self, start: int, **arrays: np.ndarray) -> None:
        """Trials ``start …`` of ``truth``, ``estimate`` and ``error`` (each (rows, 39), SI)."""
        if self._file is None:
            raise ValueError(f"results file {str(self.path)!r}: start() it first")
        if set(arrays) != set(RESULT_VARIABLES):
            raise ValueError(f"write: expected the arrays {', '.join(RESULT_VARIABLES)}; got {', '.join(arrays)}")
        rows = {a.shape[0] for a in arrays.values()}
        if len(rows) != 1:
            raise ValueError(f"write: the arrays have different numbers of trials: {sorted(rows)}")
        stop = start + rows.pop()
        if not 0 <= start <= stop <= self._trials:
            raise ValueError(f"write: trials {start}…{stop - 1} are outside 0…{self._trials - 1}")
        variables = self._file.variables
        variables["trial"][start:stop] = np.arange(start, stop)
        for name, values in arrays.items():
            variables[name][start:stop, :] = values

    def _close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

    def commit(self) -> None:
        """Close the file and move it onto the target (with the permissions an ordinary ``open`` gives)."""
        if self._file is None:
            raise ValueError(f"results file {str(self.path)!r}: nothing was written")
        self._close()
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self.temporary, 0o666 & ~umask)
        os.replace(self.temporary, self.path)
        self.committed = True

    def discard(self) -> None:
        """Close and remove the temporary file (the target is left as it was)."""
        try:
            self._close()
        finally:
            if not self.committed and os.path.exists(self.temporary):
                os.remove(self.temporary)

    def __enter__(self) -> ResultsFile:
        return self

    def __exit__(self, *exc_info) -> None:
        self.discard()


def write_results(dataset: xr.Dataset, path: str | os.PathLike, block: int = CHUNK_TRIALS) -> None:
    """Write a run's per-trial Dataset (:func:`plansim.runner.run`) as the results file
    :func:`plansim.runner.run_summary` streams (NetCDF-4, the same layout), whole or not at all.

    ``segment_mean``, if present, is not written (as for ``plansim run --out``).
    """
    trials = dataset.sizes["trial"]
    template = dataset[list(RESULT_VARIABLES)].isel(trial=slice(0, 0))
    with ResultsFile(path) as out:
        out.check_space(trials)
        out.start(template, trials)
        for start in range(0, trials, block):
            part = dataset.isel(trial=slice(start, start + block))
            out.write(start, **{name: part[name].values for name in RESULT_VARIABLES})
        out.commit()
