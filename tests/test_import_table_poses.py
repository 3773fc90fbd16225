"""``plansim import --poses table``: a lab's table log, its poses set by the table, fits all 39 parameters.

A log taken on a rate table (JJF 2003 clause 6: the 12 positions, each body axis up and down at two headings, and
the rate tests about the vertical) holds no heading: a plain log has no heading reference. Imported as placed by
hand, each pose's tilt is a nuisance of the fit and takes up the cross-couplings with it, so the fit identifies 21
of the 39 parameters of eq. (1)/(2). With ``--poses table`` each axis-up pose and each turn about the vertical is
``known`` to the table's grade, its heading NaN (not logged); the fit takes the table's position errors as Type B
inputs and the Earth rate's horizontal part, over the unknown heading, as one more (docs/fitting.md).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from plansim.cli import main
from plansim.fit import fit_recording, resolve_site
from plansim.io.log_import import TABLE_POSE_TILT, import_log
from plansim.io.recording import read_recording
from plansim.io.scenario_file import load_scenario
from plansim.runner import simulate_and_record
from plansim.simulate.chunks import simulate_recording
from plansim.uncertainty.metrology.coverage import coverage_tolerance
from plansim.uncertainty.metrology.propagation import coverage_factor
from test_log_import import write_synthetic

#: linear_gaussian (the GUM holds: Gaussian noise, dithered quantiser, Gaussian table errors) with the Earth rate on,
#: so that the unknown headings matter: 15 deg/h at 39.9 deg N, against a gyro segment mean's 1-3 deg/h
_OVERRIDES = ["environment.earth_rate=true"]


def _table_log(path, scenario, seed: int, trial: int):
    """The simulated run written as a lab's acquisition writes it: time (with the table's settle times as gaps), the
    six channels in SI and the table's rate (deg/s, its controller's). Returns the truth (39,)."""
    recording = simulate_and_record(scenario, seed=seed, trial=trial)
    _, _, truth = simulate_recording(scenario, seed, trial)
    rate = np.concatenate([np.full(s.samples, math.degrees(s.rate)) for s in recording.schedule.segments])
    write_synthetic(path, recording.time, recording.samples, extra={"table_dps": rate})
    return truth


def _joint(recording, scenario):
    fit = fit_recording(recording, resolve_site(scenario=scenario), turntable=scenario.turntable,
                        reference_gravity=scenario.reduction.reference_gravity)
    return fit, next(m for m in fit.methods if m.name == "joint_wls")


def test_a_table_log_imported_with_its_poses_set_by_the_table_fits_all_39_within_their_uncertainty(tmp_path,
                                                                                                   capsys):
    """8 simulated runs written as table logs (18 poses and 27 steady turns each), imported with ``--poses table``:
    every pose and turn is known, all 39 parameters are identified, and the joint fit covers the truth at 95 %
    pooled over the 312 values within the binomial tolerance at z = 3 (0.913-0.987; measured 0.974, r.m.s. z 0.96).
    The same log imported as placed by hand (the default) identifies 21: the cross-couplings of Kg and Ka go with
    the tilts, and P with them."""
    scenario = load_scenario("linear_gaussian", overrides=_OVERRIDES)
    log = tmp_path / "table.csv"
    truth = _table_log(log, scenario, seed=61, trial=0)
    rec = tmp_path / "rec.nc"
    assert main(["import", str(log), "--out", str(rec), "--time", "time", "--table-rate-column", "table_dps",
                 "--poses", "table"]) == 0
    out = capsys.readouterr().out
    assert "poses: set by a table (--poses table): orientation = known for 18 of the 18 static poses" in out, out
    recording = read_recording(rec)
    segments = [s for s in recording.schedule.segments if s.test != "move"]
    assert [s.test for s in segments].count("rotation") == 27
    assert all(s.orientation == "known" and not s.heading_known for s in segments)
    assert recording.schedule.notes["import"]["poses"] == "table"
    fit, joint = _joint(recording, scenario)
    assert len(fit.identified) == 39 and not fit.placed
    hits = [np.abs(joint.estimate - truth) <= np.array([coverage_factor(nu) for nu in joint.dof]) * joint.u]
    # the same log as placed by hand: the tilts take up the cross-couplings
    by_hand = import_log(log, time_column="time", table_rate_column="table_dps")
    hand_fit, _ = _joint(by_hand.recording, scenario)
    assert len(hand_fit.identified) == 21
    assert not any(name[:2] in ("Kg", "Ka") and name[2] != name[3] for name in hand_fit.identified)
    for trial in range(1, 8):
        truth = _table_log(log, scenario, seed=61, trial=trial)
        imported = import_log(log, time_column="time", table_rate_column="table_dps", poses="table")
        fit, joint = _joint(imported.recording, scenario)
        assert len(fit.identified) == 39
        assert not any("Were they placed by hand?" in note for note in fit.notes)  # honest table poses: no question
        hits.append(np.abs(joint.estimate - truth) <= np.array([coverage_factor(nu) for nu in joint.dof]) * joint.u)
    hits = np.concatenate(hits)
    assert abs(hits.mean() - 0.95) <= coverage_tolerance(hits.size, 0.95, 3.0), (hits.mean(), hits.size)


def test_a_pose_the_table_could_not_have_set_keeps_its_hand_placed_orientation(tmp_path):
    """With ``--poses table``, a pose whose specific force lies 8 deg from every body axis (more than
    TABLE_POSE_TILT, 5 deg: beyond what a MEMS unit's misalignments and biases tilt it by) is not one of the table's
    axis-up positions: it stays hand-placed (its tilt fitted), named in a warning; the others are known. A value of
    --poses that is not allowed is refused, naming the option."""
    scenario = load_scenario("linear_gaussian", overrides=_OVERRIDES)
    recording = simulate_and_record(scenario, seed=62, trial=0)
    samples = recording.samples.copy()
    first = recording.schedule.segments[0]
    assert first.test == "multi_position" and first.up == "+x"
    c, s = math.cos(math.radians(8.0)), math.sin(math.radians(8.0))
    ax, ay = samples[:first.samples, 3].copy(), samples[:first.samples, 4].copy()
    samples[:first.samples, 3], samples[:first.samples, 4] = c * ax - s * ay, s * ax + c * ay  # tipped 8 deg
    log = tmp_path / "tipped.csv"
    rate = np.concatenate([np.full(seg.samples, math.degrees(seg.rate)) for seg in recording.schedule.segments])
    write_synthetic(log, recording.time, samples, extra={"table_dps": rate})
    result = import_log(log, time_column="time", table_rate_column="table_dps", poses="table")
    statics = [seg for seg in result.recording.schedule.segments if seg.test == "static"]
    assert statics[0].orientation == "approximate" and all(seg.orientation == "known" for seg in statics[1:])
    assert math.degrees(TABLE_POSE_TILT) == pytest.approx(5.0)
    warned = [w.message for w in result.warnings if w.name == "not_a_table_pose"]
    assert len(warned) == 1 and "1 of the 18 static pose(s)" in warned[0], warned
    tilt = re.search(r"\(([0-9.]+) deg from \+x\)", warned[0])  # 8 deg, give or take the unit's own misalignment
    assert tilt is not None and abs(float(tilt.group(1)) - 8.0) < 0.5, warned
    with pytest.raises(ValueError, match=r"--poses 'bench'; allowed: hand, table"):
        import_log(log, time_column="time", poses="bench")


def test_poses_placed_by_hand_but_imported_as_set_by_a_table_are_questioned(tmp_path):
    """A hand-held session of twelve poses near the six axes (each placed twice, 1.5 deg off its axis at random, a
    consumer unit, plansim.simulate.hand_session) imported with ``--poses table``: the accelerometers scatter between
    the repeats of one up-axis far beyond the table's grade (the repeated settings' verdict, a chi-square test at
    0.5 % per channel), and `plansim fit` asks whether the poses were placed by hand. Imported as placed by hand, the
    note is not given (no pose is said to be the table's)."""
    from scipy.spatial.transform import Rotation

    from plansim.fit.site import Site
    from plansim.simulate.hand_session import consumer_unit, hand_session

    rng = np.random.default_rng(5)
    ups = [("y", 90.0), ("y", -90.0), ("x", -90.0), ("x", 90.0), ("x", 0.0), ("x", 180.0)]  # +x, -x, +y, -y, +z, -z
    poses = []
    for axis, angle in ups * 2:
        off = Rotation.from_rotvec(np.radians(1.5) * np.append(rng.normal(size=2) / math.sqrt(2.0), 0.0))
        poses.append((off * Rotation.from_euler(axis, angle, degrees=True)).as_matrix())
    site = Site(math.radians(45.0), 100.0, earth_rate=False)
    session = hand_session(consumer_unit(5), np.array(poses), seed=5, gravity=site.gravity, gyro_noise=8.7e-4,
                           accel_noise=9.8e-3)
    log = tmp_path / "hand.csv"
    write_synthetic(log, session.time, session.samples)
    as_table = import_log(log, time_column="time", poses="table")
    known = [s for s in as_table.recording.schedule.segments if s.test == "static" and s.orientation == "known"]
    assert len(known) >= 10, [s.label for s in as_table.recording.schedule.segments]
    fit = fit_recording(as_table.recording, site)
    asked = [n for n in fit.notes if "Were they placed by hand?" in n]
    assert len(asked) == 1 and "re-import without --poses table" in asked[0], fit.notes
    by_hand = fit_recording(import_log(log, time_column="time").recording, site)
    assert not any("Were they placed by hand?" in n for n in by_hand.notes)


def test_an_independent_table_log_gives_the_accelerometers_cross_couplings_within_their_uncertainty(tmp_path):
    """A table log written without plansim's simulator (``test_moves._table_log``: the attitude integrated exactly,
    Ka = I + 1e-3 normal errors, biases of 0.02 m/s^2, g = 9.80 m/s^2, no Earth rate), the table turning the unit by
    quarter turns about its axes until every axis has been up and down (14 poses). Imported with ``--poses table``
    and fitted without the moves, at the site whose normal gravity is the log's 9.80 m/s^2 (38.08 deg N, 0 m): the
    accelerometers' six cross-couplings are identified (24 parameters: Ka, Ba, Bg and G), and every identified
    parameter the log has a truth for lies within 3.3 u of it (0.1 % two-sided each; measured on seeds 0-5: at most
    2.9 u, the cross-couplings at most 0.64 u, their u being the Table 1 grade's while this table is exact). Placed by
    hand (the default), the same log identifies 18, none of the cross-couplings. With the moves (the table's quarter
    turns, the gravity sequence), the gyros' cross-couplings come out in the case frame, within 3.3 u of the truth
    (measured on seeds 0 and 1: 1.7 u at most), where poses placed by hand give them relative to the accelerometer
    triad only."""
    from plansim.fit.site import Site
    from plansim.model.parameters import PARAMETER_INDEX
    from test_moves import _table_log, _table_log_truth, _write_log

    turns = [(1, 90)] * 4 + [(2, 90)] * 4 + [(0, 90)] + [(1, 90)] * 4
    site = Site(math.radians(38.08184096023697), 0.0, earth_rate=False)
    assert site.gravity == pytest.approx(9.80, abs=1e-9)
    cross = {f"Ka{a}{b}" for a in "xyz" for b in "xyz" if a != b}
    for seed in range(3):
        t, x, _ = _table_log(turns, seed=seed)
        log = _write_log(tmp_path / f"table{seed}.csv", t, x)
        recording = import_log(log, time_column="time", units="deg/s,m/s^2", poses="table").recording
        assert {s.up for s in recording.schedule.segments if s.test == "static"} == {"+x", "-x", "+y", "-y", "+z",
                                                                                       "-z"}
        fit = fit_recording(recording, site, moves=False)
        identified = set(fit.identifiability.identified)
        assert len(identified) == 24 and cross <= identified, sorted(identified)
        truth = _table_log_truth(seed)
        for name in identified & set(truth):
            k = PARAMETER_INDEX[name]
            assert abs(fit.joint.estimate[k] - truth[name]) < 3.3 * fit.joint.u[k], (seed, name)
    by_hand = fit_recording(import_log(log, time_column="time", units="deg/s,m/s^2").recording, site, moves=False)
    assert len(by_hand.identifiability.identified) == 18 and not cross & set(by_hand.identifiability.identified)
    # the table's quarter turns, fitted as the moves between poses (the gravity sequence): from poses the table set,
    # Kg's cross-couplings are in the case frame (as placed by hand, only relative to the accelerometer triad)
    t, x, Kg = _table_log(turns, seed=0)
    log = _write_log(tmp_path / "table_moves.csv", t, x)
    moves = fit_recording(import_log(log, time_column="time", units="deg/s,m/s^2", poses="table").recording,
                          site).moves
    kg_cross = {f"Kg{a}{b}" for a in "xyz" for b in "xyz" if a != b}
    assert kg_cross <= set(moves.identified) and not moves.relative, (moves.identified, moves.relative)
    for name in moves.identified:
        k, i, j = PARAMETER_INDEX[name], "xyz".index(name[2]), "xyz".index(name[3])
        assert abs(moves.method.estimate[k] - Kg[i, j]) < 3.3 * moves.method.u[k], name
