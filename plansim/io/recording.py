"""Recordings: the raw output of one calibration run, as a lab's data acquisition produces it.

A :class:`Recording` is the segment table (a :class:`~plansim.schedule.segments.Schedule`) plus every
raw sample of the six channels ``gx, gy, gz`` (rad/s) and ``ax, ay, az`` (m/s²), concatenated
segment by segment in schedule order, plus provenance attributes (and, for measured logs, the site, the
measured time and a temperature channel). Simulated recordings come from
:func:`plansim.runner.simulate_and_record`; measured ones are read with :func:`read_recording`. Both go through the
same validation, so a measured file that reads is one the rest of plansim can use.

This module is the public face; the work is done by one module per job:

- :mod:`plansim.io.recording_data` — the :class:`Recording` data class and its checks, the time axis;
- :mod:`plansim.io.recording_columns` — the segment table's fields and the checks that turn the
  columns read from a file into a Recording;
- :mod:`plansim.io.recording_netcdf` — ``.nc``: one NetCDF-3 file (xarray, ``engine="scipy"``),
  dimensions ``sample`` and ``segment``; and the conversion to and from :class:`xarray.Dataset`;
- :mod:`plansim.io.recording_csv` — ``.csv``: two files, the samples at the given path and the
  segment table beside it at ``<stem>.segments.csv``.

docs/recording.md describes every field. Time convention: see :mod:`plansim.io.recording_data`.
"""

from __future__ import annotations

import os
from pathlib import Path

from plansim.io.recording_columns import OPTIONAL_FIELDS, SEGMENT_FIELDS
from plansim.io.recording_csv import (
    CSV_CHANNEL_COLUMNS,
    CSV_SAMPLE_COLUMNS,
    CSV_SEGMENT_COLUMNS,
    CSV_TEMPERATURE_COLUMN,
    SEGMENT_TABLE_SUFFIX,
    read_csv,
    segment_table_path,
    write_csv,
)
from plansim.io.recording_data import (
    CHANNEL_LONG_NAMES,
    CHANNEL_UNITS,
    CHANNELS,
    FORMAT_NAME,
    FORMAT_VERSION,
    READABLE_VERSIONS,
    RESERVED_ATTRIBUTES,
    SITE_ATTRIBUTES,
    SOURCES,
    UNITS_DESCRIPTION,
    Recording,
    nominal_time,
    plansim_version,
    segment_first_samples,
)
from plansim.io.recording_netcdf import (
    TEMPERATURE_VARIABLE,
    dataset_to_recording,
    read_netcdf,
    recording_to_dataset,
    write_netcdf,
)

__all__ = [
    "CHANNELS", "CHANNEL_LONG_NAMES", "CHANNEL_UNITS", "CSV_CHANNEL_COLUMNS", "CSV_SAMPLE_COLUMNS",
    "CSV_SEGMENT_COLUMNS", "CSV_TEMPERATURE_COLUMN", "FORMAT_NAME", "FORMAT_VERSION", "OPTIONAL_FIELDS",
    "READABLE_VERSIONS", "RESERVED_ATTRIBUTES", "SEGMENT_FIELDS", "SEGMENT_TABLE_SUFFIX", "SITE_ATTRIBUTES",
    "SOURCES", "SUFFIXES", "TEMPERATURE_VARIABLE", "UNITS_DESCRIPTION", "Recording", "dataset_to_recording",
    "nominal_time", "plansim_version", "read_recording", "recording_to_dataset", "segment_first_samples",
    "segment_table_path", "write_recording",
]

SUFFIXES = (".nc", ".csv")


def _check_path(path: str | os.PathLike) -> Path:
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path = {path!r}: expected a file name (str or os.PathLike)")
    target = Path(path)
    if target.suffix.lower() not in SUFFIXES:
        raise ValueError(f"recording file {str(target)!r}: suffix {target.suffix!r} not supported; allowed: "
                         f"{', '.join(SUFFIXES)} (.csv writes a second file <stem>{SEGMENT_TABLE_SUFFIX})")
    if target.name.lower().endswith(SEGMENT_TABLE_SUFFIX):
        samples_name = target.name[:-len(SEGMENT_TABLE_SUFFIX)] + ".csv"
        raise ValueError(f"recording file {str(target)!r} names a segment table; give the samples file "
                         f"{str(target.with_name(samples_name))!r}, its table is found beside it")
    return target


def write_recording(recording: Recording, path: str | os.PathLike) -> None:
    """Write *recording* to *path*: ``.nc`` (NetCDF-3) or ``.csv`` (samples + ``<stem>.segments.csv``).

    Files are written whole or not at all (temporary file beside the target, then rename); for CSV,
    if either file fails neither new file remains. Existing files are replaced.

    Raises
    ------
    ValueError
        The suffix is not ``.nc`` or ``.csv``, or the folder does not exist.
    """
    if not isinstance(recording, Recording):
        raise TypeError(f"recording: expected a plansim Recording, got {type(recording).__name__}")
    target = _check_path(path)
    if target.suffix.lower() == ".nc":
        write_netcdf(recording, target)
    else:
        write_csv(recording, target)


def read_recording(path: str | os.PathLike) -> Recording:
    """Read a recording written by :func:`write_recording` or prepared by a lab (docs/recording.md).

    Parameters
    ----------
    path : str or os.PathLike
        ``.nc`` file, or the samples ``.csv`` (its segment table ``<stem>.segments.csv`` is read too).

    Raises
    ------
    ValueError
        Unsupported suffix, missing file, missing column or variable, a non-finite or non-numeric value,
        a wrong unit, or a number of samples that disagrees with the segment table; the message names
        the file, the column and what is expected.
    """
    target = _check_path(path)
    if not target.is_file():
        raise ValueError(f"recording file {str(target)!r} does not exist")
    if target.suffix.lower() == ".nc":
        return read_netcdf(target)
    return read_csv(target)
