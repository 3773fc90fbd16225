"""Recordings as NetCDF-3 files (``.nc``) and as :class:`xarray.Dataset` objects.

One file, written by xarray with ``engine="scipy"`` (no extra library): dimensions ``sample`` and
``segment``, the six channels and the time over ``sample``, the segment table over ``segment``,
provenance in the global attributes (docs/recording.md describes every variable).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from plansim.io.files import atomic_write
from plansim.io.recording_columns import (
    OPTIONAL_FIELDS,
    SEGMENT_FIELDS,
    TEXT_FIELDS,
    assemble,
    check_format_attributes,
    numeric_column,
    plain,
    schedule_from_columns,
    schedule_notes,
    schedule_notes_text,
)
from plansim.io.recording_data import (
    CHANNEL_LONG_NAMES,
    CHANNEL_UNITS,
    CHANNELS,
    FORMAT_NAME,
    FORMAT_VERSION,
    RESERVED_ATTRIBUTES,
    Recording,
)

_NETCDF3_INT_MIN, _NETCDF3_INT_MAX = -(2**31), 2**31 - 1
#: the per-sample temperature channel (the segment table's ``temperature`` is one value per segment)
TEMPERATURE_VARIABLE = "sample_temperature"


def recording_to_dataset(recording: Recording) -> xr.Dataset:
    """The recording as an :class:`xarray.Dataset` with dimensions ``sample`` and ``segment``.

    Variables over ``sample``: ``gx gy gz`` (rad/s), ``ax ay az`` (m/s^2); coordinates ``time`` (s, global
    axis) and ``segment_index``; ``sample_temperature`` (degC) when the recording has a temperature
    channel. Over ``segment``: the segment table (``label test group up heading rate rate_axis dwell settle
    sample_rate temperature first_sample samples orientation angle``). Every variable has ``units``
    (numeric ones) and ``long_name`` attributes. Dataset attributes: the recording's ``attrs`` plus
    ``format``, ``format_version``, ``schedule_procedure`` and ``schedule_notes`` (JSON).
    """
    if not isinstance(recording, Recording):
        raise TypeError(f"recording: expected a plansim Recording, got {type(recording).__name__}")
    segments = recording.schedule.segments
    table = {
        "label": np.array([s.label for s in segments], dtype=object),
        "test": np.array([s.test for s in segments], dtype=object),
        "group": np.array([s.group for s in segments], dtype=np.int64),
        "up": np.array([s.up for s in segments], dtype=object),
        "heading": np.array([s.heading for s in segments], dtype=np.float64),
        "rate": np.array([s.rate for s in segments], dtype=np.float64),
        "rate_axis": np.array([s.rate_axis for s in segments], dtype=object),
        "dwell": np.array([s.dwell for s in segments], dtype=np.float64),
        "settle": np.array([s.settle for s in segments], dtype=np.float64),
        "sample_rate": np.array([s.sample_rate for s in segments], dtype=np.float64),
        "temperature": np.array([s.temperature for s in segments], dtype=np.float64),
        "first_sample": recording.first_sample,
        "samples": np.array([s.samples for s in segments], dtype=np.int64),
        "orientation": np.array([s.orientation for s in segments], dtype=object),
        "angle": np.array([s.angle for s in segments], dtype=np.float64),
    }
    data_vars = {}
    for column, name in enumerate(CHANNELS):
        data_vars[name] = ("sample", recording.samples[:, column],
                           {"units": CHANNEL_UNITS[name], "long_name": CHANNEL_LONG_NAMES[name]})
    for name, (units, long_name) in SEGMENT_FIELDS.items():
        attrs = {"long_name": long_name} if units is None else {"units": units, "long_name": long_name}
        data_vars[name] = ("segment", table[name], attrs)
    if recording.temperature is not None:
        data_vars[TEMPERATURE_VARIABLE] = ("sample", recording.temperature,
                                           {"units": "degC", "long_name": "measured temperature of each sample"})
    coords = {
        "time": ("sample", recording.time,
                 {"units": "s", "long_name": "time from the start of the schedule, settle times included"}),
        # not called "segment": a variable may not share its name with the segment dimension
        "segment_index": ("sample", recording.segment_index,
                          {"units": "1", "long_name": "segment of each sample (0-based, schedule order)"}),
    }
    attrs = {"format": FORMAT_NAME, "format_version": FORMAT_VERSION, **recording.attrs,
             "schedule_procedure": recording.schedule.procedure,
             "schedule_notes": schedule_notes_text(recording.schedule)}
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)



def dataset_to_recording(dataset: xr.Dataset, where: str = "dataset") -> Recording:
    """The inverse of :func:`recording_to_dataset`, validating every variable.

    Parameters
    ----------
    dataset : xarray.Dataset
        Variables as :func:`recording_to_dataset` makes them (``time`` and ``segment_index`` may be
        data variables or coordinates). A ``units`` attribute, where present, must be the SI unit.
    where : str
        What to call the dataset in error messages (``read_recording`` passes the file name).

    Returns
    -------
    Recording
        ``timestamps`` is ``None`` when ``time`` equals the nominal time of the schedule exactly, else
        the dataset's ``time``.

    Raises
    ------
    ValueError
        A variable is missing, has the wrong dimension, a wrong ``units`` attribute, a non-finite value,
        or the number of samples disagrees with the segment table.
    """
    if not isinstance(dataset, xr.Dataset):
        raise TypeError(f"{where}: expected an xarray Dataset, got {type(dataset).__name__}")
    attrs = {key: plain(value, where) for key, value in dataset.attrs.items()}
    check_format_attributes(attrs, where)
    procedure = str(attrs.pop("schedule_procedure", "custom"))
    notes = schedule_notes(attrs.pop("schedule_notes", None), where)
    for key in RESERVED_ATTRIBUTES:
        attrs.pop(key, None)

    def variable(name: str, dimension: str, units: str | None) -> np.ndarray | None:
        if name not in dataset.variables:
            if name in OPTIONAL_FIELDS or name == TEMPERATURE_VARIABLE:
                return None
            raise ValueError(f"{where}: variable {name!r} is missing; expected one over dimension {dimension!r}"
                             + (f" in {units}" if units else ""))
        var = dataset.variables[name]
        if var.dims != (dimension,):
            raise ValueError(f"{where}: variable {name!r} has dimensions {var.dims}; expected ({dimension!r},)")
        found_units = var.attrs.get("units")
        if units is not None and found_units is not None and plain(found_units, where) != units:
            raise ValueError(f"{where}: variable {name!r} has units {plain(found_units, where)!r}; expected {units!r} "
                             "(convert to SI before writing the file)")
        return np.asarray(var.values)

    table = {name: variable(name, "segment", units) for name, (units, _) in SEGMENT_FIELDS.items()}
    table = {name: values for name, values in table.items() if values is not None}
    for name in TEXT_FIELDS:
        if name in table:
            table[name] = [plain(value, where) for value in table[name]]
    schedule = schedule_from_columns(table, where, column_names={name: name for name in SEGMENT_FIELDS},
                                      procedure=procedure, notes=notes)
    channels = []
    for name in CHANNELS:
        values = variable(name, "sample", CHANNEL_UNITS[name])
        channels.append(numeric_column(values, where, f"variable {name!r}", CHANNEL_UNITS[name]))
    segment_index = numeric_column(variable("segment_index", "sample", "1"), where, "variable 'segment_index'", "")
    time = numeric_column(variable("time", "sample", "s"), where, "variable 'time'", "s")
    temperature = variable(TEMPERATURE_VARIABLE, "sample", "degC")
    if temperature is not None:
        temperature = numeric_column(temperature, where, f"variable {TEMPERATURE_VARIABLE!r}", "degC")
    return assemble(schedule, np.column_stack(channels), time, segment_index, attrs,
                     where=where, count_name="dimension 'sample'", segment_name="variable 'segment_index'",
                     time_name="variable 'time'", table_where=where,
                     channel_names=tuple(f"variable {name!r}" for name in CHANNELS),
                     temperature=temperature, temperature_name=f"variable {TEMPERATURE_VARIABLE!r}")


def _netcdf3_attributes(attrs: dict) -> dict:
    """NetCDF-3 has no 64-bit integer attribute: larger whole numbers (seeds) are stored as text and listed."""
    encoded, as_text = {}, []
    for key, value in attrs.items():
        if isinstance(value, int) and not _NETCDF3_INT_MIN <= value <= _NETCDF3_INT_MAX:
            encoded[key] = str(value)
            as_text.append(key)
        else:
            encoded[key] = value
    if as_text:
        encoded["integer_text_attributes"] = " ".join(as_text)
    return encoded


def write_netcdf(recording: Recording, target: Path) -> None:
    """Write *recording* to *target* as one NetCDF-3 (64-bit offset) file, atomically."""
    if recording.samples.shape[0] > _NETCDF3_INT_MAX:
        raise ValueError(f"recording file {str(target)!r}: {recording.samples.shape[0]} samples exceed what a "
                         "NetCDF-3 file indexes; write .csv instead")
    dataset = recording_to_dataset(recording)
    dataset.attrs = _netcdf3_attributes(dataset.attrs)
    atomic_write(target, lambda tmp: dataset.to_netcdf(tmp, engine="scipy", format="NETCDF3_64BIT"))


def read_netcdf(target: Path) -> Recording:
    """Read and check the NetCDF recording *target*; every problem is a ``ValueError`` naming the file."""
    where = f"recording file {str(target)!r}"
    try:
        dataset = xr.load_dataset(target, engine="scipy", decode_times=False, decode_timedelta=False)
    except Exception as exc:  # the parser, fed arbitrary bytes, fails in many ways: IndexError, KeyError, ...
        raise ValueError(f"{where}: not a readable NetCDF-3 file, or one cut short or damaged "
                         f"({type(exc).__name__}: {exc})") from None
    attrs = {key: plain(value, where) for key, value in dataset.attrs.items()}
    for key in str(attrs.pop("integer_text_attributes", "")).split():
        try:
            attrs[key] = int(attrs[key])
        except (KeyError, TypeError, ValueError):
            raise ValueError(f"{where}: integer_text_attributes lists {key!r} but attribute {key!r} = "
                             f"{attrs.get(key)!r} is not a whole number") from None
    dataset.attrs = attrs
    return dataset_to_recording(dataset, where=where)
