"""A phone app's two sensor logs, from the files to the calibration: ``plansim import GYRO --accel-log ACCEL``.

Phone apps (phyphox, the Android and iOS sensor loggers) and imu_tk write each sensor to its own file, stamped by
one clock but not sampled together and often not at one rate. Here a consumer MEMS unit is moved by hand through
24 poses (``plansim.simulate.hand_session``, 200 Hz inside the unit). The app writes the gyros at 100 Hz, each
sample the mean of two (the sensor's own averaging), in ``Gyroscope.csv``, and the accelerometers at 200 Hz,
1 ms after the gyros' clock ticks, in ``Accelerometer.csv``, with phyphox's header ("Time (s)", "X (rad/s)" …).
``plansim import`` keeps the slower log's samples and gives each the mean of the faster log's samples in its
interval (docs/measured-data.md, ``--accel-log``). The units are read from the header. ``plansim fit`` then
calibrates the gyros from the moves between the poses and the accelerometers from the poses, and the scale
factors are printed against the unit's truth with their standard uncertainty.

    python docs/examples/phone_logs.py [SEED]
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from plansim.fit import fit_recording
from plansim.fit.site import Site
from plansim.io.log_import import import_log
from plansim.model.parameters import PARAMETER_INDEX
from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

HEADER = '"Time (s)","X ({unit})","Y ({unit})","Z ({unit})"'
COLUMNS = ("X (rad/s)", "Y (rad/s)", "Z (rad/s)", "X (m/s^2)", "Y (m/s^2)", "Z (m/s^2)")


def main(seed: int) -> None:
    theta = consumer_unit(seed)
    site = Site(math.radians(45.0), 100.0, earth_rate=False)
    session = hand_session(theta, spread_poses(24, seed=seed), sample_rate=200.0, seed=seed, gyro_noise=1.2e-3,
                           accel_noise=1.4e-2, gravity=site.gravity)
    n = session.time.size // 2 * 2
    gyro_time = 0.5 * (session.time[0:n:2] + session.time[1:n:2])
    gyro = 0.5 * (session.samples[0:n:2, :3] + session.samples[1:n:2, :3])
    with tempfile.TemporaryDirectory() as folder:
        logs = Path(folder) / "Gyroscope.csv", Path(folder) / "Accelerometer.csv"
        for path, time, values, unit in ((logs[0], gyro_time, gyro, "rad/s"),
                                         (logs[1], session.time + 1e-3, session.samples[:, 3:], "m/s^2")):
            np.savetxt(path, np.column_stack([time, values]), delimiter=",", header=HEADER.format(unit=unit),
                       comments="", fmt="%.9g")
        imported = import_log(logs[0], accel_log=logs[1], columns=COLUMNS, time_column="Time (s)")
    for note in imported.table.pairing:
        print(note)
    kinds = [s.test for s in imported.recording.schedule.segments]
    print(f"found: {kinds.count('static')} poses, {kinds.count('move')} moves, {kinds.count('rotation')} turns; "
          f"units {', '.join(dict.fromkeys(imported.units))} from the header")
    fit = fit_recording(imported.recording, site)
    for name, method in (("Kgxx", fit.moves.method), ("Kgyy", fit.moves.method), ("Kgzz", fit.moves.method),
                         ("Kaxx", fit.joint), ("Kayy", fit.joint), ("Kazz", fit.joint)):
        k = PARAMETER_INDEX[name]
        print(f"{name}: {method.estimate[k]:.5f} ± {method.u[k]:.5f} (truth {theta[k]:.5f})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
