"""A raw, headerless log in counts, as imu_tk's loggers write it, from the file to the gyro scale factors.

A consumer MEMS unit is moved by hand through 24 poses (``plansim.simulate.hand_session``: 5 s rests, 3 s moves,
100 Hz). Its samples are written as a plain text log the way many loggers do: no header line, columns separated
by spaces, in imu_tk's order ``time ax ay az gx gy gz``, raw 16-bit counts (16.4 counts per deg/s, 2048 per g).
``plansim import`` reads it with the columns named by position, finds the poses and moves from the data alone,
and ``plansim fit`` calibrates the gyros from the moves between the poses (docs/measured-data.md,
docs/fitting.md). The gyro scale factors are printed against the unit's truth, with their standard uncertainty.

    python docs/examples/headerless_log.py [SEED]
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

GYRO_COUNTS = 16.4 / math.radians(1.0)  # counts per rad/s
ACCEL_COUNTS = 2048.0 / 9.80665  # counts per m/s^2


def main(seed: int) -> None:
    theta = consumer_unit(seed)
    session = hand_session(theta, spread_poses(24, seed=seed), seed=seed, gyro_noise=8.7e-4, accel_noise=9.8e-3)
    counts = np.round(np.column_stack([session.samples[:, 3:] * ACCEL_COUNTS, session.samples[:, :3] * GYRO_COUNTS]))
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "imu.txt"
        np.savetxt(log, np.column_stack([session.time, counts]), fmt=["%.4f"] + ["%d"] * 6)  # no header, spaces
        print(log.read_text().splitlines()[0], " <- the log's first line")
        imported = import_log(log, columns=("5", "6", "7", "2", "3", "4"), time_column="1", units="deg/s,g",
                              scale="16.4,2048")
    kinds = [s.test for s in imported.recording.schedule.segments]
    print(f"found: {kinds.count('static')} poses, {kinds.count('move')} moves, {kinds.count('rotation')} turns")
    fit = fit_recording(imported.recording, Site(math.radians(45.0), 100.0, earth_rate=False))
    moves = fit.moves.method
    for name in ("Kgxx", "Kgyy", "Kgzz"):
        k = PARAMETER_INDEX[name]
        print(f"{name}: {moves.estimate[k]:.5f} ± {moves.u[k]:.5f} (truth {theta[k]:.5f})")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
