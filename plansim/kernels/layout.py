"""The kernels' array layouts, named in one place: the draws vector, channel order, argument packing.

Every index into a packed array that the kernels and their callers share is named here, so that no
literal offset stands anywhere else. The kernels read these module constants as compile-time
integers (numba freezes module globals), so naming them costs nothing at run time.

Draws vector
------------
One trial's *systematic draws*, length :func:`draws_length` ``= HEAD + PER_SEGMENT·S``:

====================================  ===============================================================
``[TRUTH]`` = ``[0:39]``              the unit's 39 parameters (order of ``plansim.model.parameters``)
``[FIXTURE]`` = ``[39:42]``           fixture misalignment, rotation vector of the case in the fixture, rad
``[TILT]`` = ``[42:44]``              platform tilt about East and North, rad
``[RATE_SYSTEMATIC]`` = ``[44]``      rate error, systematic (relative)
``[PERPENDICULARITY]`` = ``[45:51]``  axis perpendicularity, two components per rate axis x, y, z, rad
``segment_base(s) + k``               segment *s*: ``SEG_POSITION_ACCURACY + 2·axis`` and
                                      ``SEG_POSITION_REPEATABILITY + 2·axis`` (rad, axis x, y, z),
                                      ``SEG_RATE_ERROR`` (relative), ``SEG_PHASE`` (start angle θ0, rad)
====================================  ===============================================================

Argument packing
----------------
``error_kind``/``error_scale`` (7,) in the order :data:`TABLE_ERRORS`; ``sensor`` (8, 3) rows
:data:`EFFECT_ROWS`; ``acquisition`` (6,) :data:`ACQUISITION_FIELDS`; ``noise`` (6, 4) columns
:data:`NOISE_COLUMNS` per channel of :data:`CHANNELS`; ``noise_times`` (3,) :data:`NOISE_TIMES`.
"""

from __future__ import annotations

import numpy as np

# ---------------------------------------------------------------------------------------- channels
#: output channels of the MIMU, in the order of every (…, 6) array: gyros x, y, z, then accelerometers
CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")
N_CHANNELS = 6
#: first channel of each sensor kind (0 gyro, 1 accelerometer): channel = 3·kind + axis
GYRO_CHANNELS = slice(0, 3)
ACCEL_CHANNELS = slice(3, 6)

# ------------------------------------------------------------------------------------ draws vector
N_TRUTH = 39
TRUTH = slice(0, N_TRUTH)
#: the parameter vector inside ``[TRUTH]`` (order of ``plansim.model.parameters.PARAMETER_NAMES``, which a
#: test holds equal to this): Kg row-major, Bg, G row-major, Ka row-major, Ba, then P's six off-diagonal
#: entries in the order :data:`P_ENTRIES`
KG_FIRST = 0
BG_FIRST = 9
G_FIRST = 12
KA_FIRST = 21
BA_FIRST = 30
P_FIRST = 33
P_ENTRIES = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
FIXTURE_FIRST = 39
FIXTURE = slice(FIXTURE_FIRST, FIXTURE_FIRST + 3)
TILT_FIRST = 42
TILT = slice(TILT_FIRST, TILT_FIRST + 2)
RATE_SYSTEMATIC = 44
PERPENDICULARITY_FIRST = 45
PERPENDICULARITY = slice(PERPENDICULARITY_FIRST, PERPENDICULARITY_FIRST + 6)
HEAD = 51
PER_SEGMENT = 8
SEG_POSITION_ACCURACY = 0  # + 2·axis
SEG_POSITION_REPEATABILITY = 1  # + 2·axis
SEG_RATE_ERROR = 6
SEG_PHASE = 7


def segment_base(s: int) -> int:
    """Index of segment *s*'s first entry in the draws vector."""
    return HEAD + PER_SEGMENT * s


def draws_length(n_segments: int) -> int:
    """Length of the draws vector of a schedule of *n_segments* segments."""
    return HEAD + PER_SEGMENT * n_segments


def perpendicularity_index(axis: int, component: int) -> int:
    """Index of component *component* (0, 1) of the perpendicularity error of rate axis *axis* (0 x, 1 y, 2 z)."""
    return PERPENDICULARITY_FIRST + 2 * axis + component


# ------------------------------------------------------------------------------- random streams
# Integer constants that kernels pass to other kernels are numpy scalars, not Python ints: numba
# types a Python int argument as a literal and compiles the callee once per distinct value.
STREAM_SYSTEMATIC = np.int64(0)  # truth spread and table/fixture errors
STREAM_NOISE = np.int64(1)  # sensor noise, drift and rate smoothness

# ---------------------------------------------------------------------------- argument packing
#: order of ``error_kind`` / ``error_scale`` (kind 0 = uniform ± scale, 1 = normal σ = scale)
TABLE_ERRORS = ("position_accuracy", "position_repeatability", "axis_perpendicularity", "platform_tilt",
                "fixture_perpendicularity", "rate_error_systematic", "rate_error_per_point")
ERR_POSITION_ACCURACY = 0
ERR_POSITION_REPEATABILITY = 1
ERR_AXIS_PERPENDICULARITY = 2
ERR_PLATFORM_TILT = 3
ERR_FIXTURE_PERPENDICULARITY = 4
ERR_RATE_SYSTEMATIC = 5
ERR_RATE_PER_POINT = 6

#: rows of the ``sensor`` effects array (3 columns: x, y, z)
EFFECT_ROWS = ("gyro_nonlinearity_quadratic", "gyro_nonlinearity_cubic", "gyro_asymmetry", "accel_second_order",
               "gyro_bias_temperature_coefficient", "gyro_scale_temperature_coefficient",
               "accel_bias_temperature_coefficient", "accel_scale_temperature_coefficient")
EFF_GYRO_QUADRATIC = 0
EFF_GYRO_CUBIC = 1
EFF_GYRO_ASYMMETRY = 2
EFF_ACCEL_SECOND_ORDER = 3
EFF_GYRO_BIAS_TEMPERATURE = 4
EFF_GYRO_SCALE_TEMPERATURE = 5
EFF_ACCEL_BIAS_TEMPERATURE = 6
EFF_ACCEL_SCALE_TEMPERATURE = 7

#: ``acquisition`` (6,): per sensor kind (0 gyro, 1 accelerometer) the output range, the quantiser
#: step and the full scale; entry ``ACQ_<FIELD> + kind``
ACQUISITION_FIELDS = ("gyro_output_range", "accel_output_range", "gyro_step", "accel_step",
                      "gyro_full_scale", "accel_full_scale")
ACQ_RANGE = 0
ACQ_STEP = 2
ACQ_FULL_SCALE = 4

#: columns of ``noise`` (6, 4), one row per channel
NOISE_COLUMNS = ("white", "bias_instability_sigma", "random_walk", "markov_sigma")
NOISE_WHITE = 0
NOISE_BIAS_INSTABILITY = 1
NOISE_RANDOM_WALK = 2
NOISE_MARKOV = 3

#: ``noise_times`` (3,)
NOISE_TIMES = ("bias_instability_correlation_time", "markov_correlation_time", "drift_update_interval")
TIME_BIAS_INSTABILITY = 0
TIME_MARKOV = 1
TIME_DRIFT_UPDATE = 2
