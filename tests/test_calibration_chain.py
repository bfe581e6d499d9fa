"""Uncertainty through the chain a technician runs: each step's 1-sigma includes the errors of the
steps it used.

Seeded Monte Carlo of the chains "tool, then turntable, then workpiece" and "tool, then track" in
the example cells, every step calibrated into the cell as ``robotcell calibrate --cell`` does it
(the tool's recorded error sources go with it). For every reported position and angle the spread
of (error / reported 1-sigma) must lie in 0.8-1.25. With 200 trials the spread of a correct
1-sigma is 1 +- 0.05 (chi-square with 200 degrees of freedom): 0.8 and 1.25 are 4.1 and 4.9
standard deviations away, so over the 31 quantities a correct propagation fails with a
probability below 0.1 %; leaving out the tool's error (the spread of the turntable origin along Z
is then 3 times its 1-sigma) cannot pass. Of the GOOD verdicts fewer than 1 % may be more than 4
sigma off (a correct 1-sigma puts 6e-5 of a Gaussian there).
"""

import json
from dataclasses import replace

import numpy as np
from ruamel.yaml import YAML
from scipy.spatial.transform import Rotation
from touch_helpers import pose_error, retouched

from robotcell.calibration.result import CalibrationResult
from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.kinematics.transforms import make_pose, transform_points
from robotcell.studies.simulate import simulate

NOISE = 1e-4
TRIALS = 200
EXAMPLE = "examples/cell_kr16_track_turntable.yaml"


def cells():
    """The example cell on its track, and the same cell with the robot fixed at track 2.5 m."""
    track_cell = Cell.load(EXAMPLE)
    fixed = replace(track_cell, track=None, T_world_R=track_cell.frame_pose("robot", track=2.5))
    return track_cell, fixed


def z_scores(T_est, T_true, sigma_position, sigma_rotation):
    return pose_error(T_est, T_true) / np.r_[sigma_position, sigma_rotation]


def test_each_step_carries_the_error_of_the_steps_before_it():
    track_cell, fixed = cells()
    tool = fixed.tools["pointer"].T_F_TCP
    designs = {"tcp": simulate(fixed, "tcp", noise=0.0, tool="pointer"),
               "turntable": simulate(fixed, "turntable", noise=0.0, tool="pointer"),
               "workpiece": simulate(fixed, "workpiece", noise=0.0, tool="pointer",
                                     frame="part"),
               "track": simulate(track_cell, "track", noise=0.0, tool="pointer")}
    refs = designs["track"].keywords()["references"]
    rng = np.random.default_rng(1)
    z = {"tool": [], "turntable": [], "workpiece": [], "track": []}
    good = off = 0
    for _ in range(TRIALS):
        t = cellcal.tcp(fixed, retouched(designs["tcp"], fixed, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        r = t.result
        z["tool"].append(z_scores(r.values["T_F_TCP"], tool, r.sigma["T_F_TCP_position"],
                                  r.sigma["T_F_TCP_rotation"]))
        steps = [(r, z["tool"][-1])]
        tt = cellcal.turntable(t.cell, retouched(designs["turntable"], fixed, tool, rng, NOISE),
                               tool="pointer", sigma=NOISE, height=-0.05)
        r = tt.result
        z["turntable"].append(z_scores(r.values["T_world_B"], fixed.turntable.T_parent_B,
                                       r.sigma["T_world_B_position"],
                                       r.sigma["T_world_B_rotation"]))
        steps.append((r, z["turntable"][-1]))
        wp = cellcal.workpiece(tt.cell, retouched(designs["workpiece"], fixed, tool, rng, NOISE),
                               "part", tool="pointer", sigma=NOISE)
        r = wp.result
        z["workpiece"].append(z_scores(r.values["T_B_W"], fixed.frames["part"].pose,
                                       r.sigma["T_B_W_position"], r.sigma["T_B_W_rotation"]))
        steps.append((r, z["workpiece"][-1]))
        # The same calibrated tool on the robot of the track cell.
        on_track = replace(track_cell, tools={**track_cell.tools,
                                              "pointer": t.cell.tools["pointer"]})
        tr = cellcal.track(on_track, retouched(designs["track"], track_cell, tool, rng, NOISE),
                           references=refs, tool="pointer", sigma=NOISE)
        r = tr.result
        z["track"].append(np.r_[
            z_scores(r.values["T_L_R"], track_cell.track.T_L_R0, r.sigma["T_L_R_position"],
                     r.sigma["T_L_R_rotation"]),
            (r.values["scale"] - track_cell.track.scale) / r.sigma["scale"]])
        steps.append((r, z["track"][-1]))
        for result, zs in steps:
            if result.verdict.level == "good":
                good += 1
                off += bool(np.max(np.abs(zs)) > 4.0)
    spreads = {k: np.sqrt(np.mean(np.square(v), axis=0)) for k, v in z.items()}
    for name, spread in spreads.items():
        assert np.all((spread > 0.8) & (spread < 1.25)), (name, np.round(spread, 3))
    assert good >= TRIALS and off < 0.01 * good, (good, off)


def test_a_turntable_result_that_is_the_cells_keeps_what_it_shares_with_the_tool():
    """``workpiece(turntable=...)`` with the result the cell's turntable came from, read from its
    JSON (which holds its total covariance only): the cell's recorded error sources are used (the
    tool's error is then counted once, and largely cancels in T_B_W), so the 1-sigma is the one
    without the result; a different turntable stays a source of its own."""
    _, fixed = cells()
    tool = fixed.tools["pointer"].T_F_TCP
    rng = np.random.default_rng(3)
    t = cellcal.tcp(fixed, retouched(simulate(fixed, "tcp", noise=0.0, tool="pointer"), fixed,
                                     tool, rng, NOISE), "pointer", sigma=NOISE)
    tt = cellcal.turntable(t.cell, retouched(simulate(fixed, "turntable", noise=0.0,
                                                      tool="pointer"), fixed, tool, rng, NOISE),
                           tool="pointer", sigma=NOISE, height=-0.05)
    touches = retouched(simulate(fixed, "workpiece", noise=0.0, tool="pointer", frame="part"),
                        fixed, tool, rng, NOISE)
    alone = cellcal.workpiece(tt.cell, touches, "part", tool="pointer", sigma=NOISE).result
    written = json.loads(json.dumps(tt.result.to_json()))  # as `--turntable turntable.json`
    given = cellcal.TurntablePose.from_result(CalibrationResult.from_json(written),
                                              "turntable.json")
    same = cellcal.workpiece(tt.cell, touches, "part", tool="pointer", sigma=NOISE,
                             turntable=given).result
    for key in ("T_B_W_position", "T_B_W_rotation"):
        np.testing.assert_allclose(same.sigma[key], alone.sigma[key], rtol=1e-9)
    moved = replace(given, T=given.T @ make_pose(np.eye(3), [1e-3, 0.0, 0.0]))
    other = cellcal.workpiece(tt.cell, touches, "part", tool="pointer", sigma=NOISE,
                              turntable=moved).result
    assert np.all(other.sigma["T_B_W_position"] > same.sigma["T_B_W_position"])


POSITIONER = "examples/cell_kr16_positioner.yaml"
#: Trials of the chain "tool, then positioner, then workpiece". The spread of a correct 1-sigma is
#: then 1 +- 0.07 (chi-square with 100 degrees of freedom): 0.8 and 1.25 are 2.8 and 3.5 standard
#: deviations away, so over the 6 quantities a correct propagation fails with a probability of
#: about 1.5 %. Leaving the positioner out (its own error, and the tool's error it shares with the
#: workpiece's touches, which largely cancels in T_P_W) spreads the z error 0.62 and the rotation
#: about z 1.56 times the reported 1-sigma: 5 and 8 standard deviations outside. Fewer trials
#: would make the bound loose; each trial identifies the positioner (about 0.08 s).
POSITIONER_TRIALS = 100


def plate_touches(cell, rng):
    """Joint values touching frame 'part' on the positioner's plate (origin, x, xy twice, 300 mm
    apart, at tilts up to 70 deg and random tool orientations), without error, and the axis
    values (rad). Tilts beyond those of the positioner's touches (30 deg) make its error show."""
    from robotcell.cell.calibrate.simulation import DOWN, Touches
    from robotcell.kinematics.transforms import invert

    v = np.radians([[60.0, 30.0], [60.0, 30.0], [-60.0, 100.0],
                    [0.0, 0.0], [70.0, -60.0], [-45.0, 200.0]])
    p_W = np.array([[0, 0, 0], [0.3, 0, 0], [0, 0.3, 0]] * 2, dtype=float)
    T = cell.frame_pose("part", table=v)
    p = np.einsum("nij,nj->ni", T[:, :3, :3], p_W) + T[:, :3, 3]
    T_R = invert(cell.frame_pose("robot"))[None, None] @ make_pose(DOWN[None], p[:, None])
    sol = cell.robot.ik(T_R, tool=cell.tools["pointer"].T_F_TCP)
    q = np.array([sol.q[i][tuple(np.argwhere(ok)[rng.integers(ok.sum())])]
                  for i, ok in enumerate(sol.valid)])
    return Touches("workpiece", q, None, v, ["origin", "x", "xy"] * 2, truth={},
                   tool="pointer", noise=0.0), v


def test_a_workpiece_on_a_positioner_carries_the_positioners_error():
    """Tool, then positioner, then workpiece on its plate, each into the cell: the workpiece's
    touches go into the plate frame P through the calibrated chain, so its 1-sigma of T_P_W
    includes the positioner's error sources (which share the tool's)."""
    cell = Cell.load(POSITIONER)
    tool = cell.tools["pointer"].T_F_TCP
    rng = np.random.default_rng(5)
    designs = {"tcp": simulate(cell, "tcp", noise=0.0, tool="pointer"),
               "positioner": simulate(cell, "positioner", noise=0.0, tool="pointer")}
    plate, v = plate_touches(cell, rng)
    z = []
    for _ in range(POSITIONER_TRIALS):
        t = cellcal.tcp(cell, retouched(designs["tcp"], cell, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        pos = cellcal.positioner(t.cell, retouched(designs["positioner"], cell, tool, rng,
                                                   NOISE), tool="pointer", sigma=NOISE)
        touches = retouched(plate, cell, tool, rng, NOISE)
        touches["e1"], touches["e2"] = np.degrees(v[:, 0]), np.degrees(v[:, 1])
        r = cellcal.workpiece(pos.cell, touches, "part", tool="pointer", sigma=NOISE).result
        z.append(z_scores(r.values["T_P_W"], cell.frames["part"].pose,
                          r.sigma["T_P_W_position"], r.sigma["T_P_W_rotation"]))
    spread = np.sqrt(np.mean(np.square(z), axis=0))
    assert np.all((spread > 0.8) & (spread < 1.25)), np.round(spread, 3)


def test_a_calibrated_positioner_keeps_its_error_sources_in_the_cell_file(tmp_path):
    """The positioner's sources (root pose, then a, alpha, d, theta of each axis) survive the
    file, with lengths in mm; the constants that define the plate get no error."""
    cell = Cell.load(POSITIONER)
    touches = simulate(cell, "positioner", noise=NOISE, seed=2, tool="pointer").to_table()
    done = cellcal.positioner(cell, touches, tool="pointer", sigma=NOISE)
    sources = done.cell.turntable.provenance.sources
    cov = sum(f @ f.T for f in sources.values())
    assert cov.shape == (14, 14) and np.all(np.sqrt(np.diag(cov)[10:]) < 1e-10)  # the plate's
    done.cell.save(tmp_path / "cell.yaml")
    back = Cell.load(tmp_path / "cell.yaml").turntable.provenance.sources
    assert back.keys() == sources.keys()
    for k, f in sources.items():
        np.testing.assert_allclose(back[k], f, rtol=1e-5, atol=1e-12)
    written = YAML(typ="safe").load(tmp_path / "cell.yaml")["positioner"]["provenance"]
    mm_rad = np.array(written["covariance_mm_rad"])
    units = np.r_[1e3, 1e3, 1e3, 1, 1, 1, 1e3, 1, 1e3, 1, 1e3, 1, 1e3, 1]  # a and d in mm
    np.testing.assert_allclose(np.diag(mm_rad)[:10], (np.diag(cov) * units**2)[:10], rtol=1e-5)


#: Trials of the chain "tool, then external TCP": the spread of a correct 1-sigma is 1 +- 0.05
#: (chi-square with 200 degrees of freedom), so 0.8 and 1.25 are 4 and 5 standard deviations away.
#: Leaving out the reference tool's error (its touch noise only) fails the bound on the origin.
EXTERNAL_TRIALS = 200


def external_touches(cell, rng):
    """Joint values touching a fixed tool with the robot's 'pointer' (its TCP four times from
    directions 30 deg apart, two points on its +X axis and two in its XY plane, 150 mm away),
    without error, and the fixed tool's pose in the robot base."""
    from robotcell.cell.calibrate.simulation import DOWN, Touches

    T_R_X = make_pose(Rotation.from_euler("xyz", [10, -5, 30], degrees=True).as_matrix(),
                      [0.9, 0.2, 0.3])
    p_X = np.array([[0, 0, 0]] * 4 + [[0.15, 0, 0]] * 2 + [[0.05, 0.15, 0]] * 2, dtype=float)
    roles = ["tcp"] * 4 + ["x"] * 2 + ["xy"] * 2
    R = DOWN[[62, 74, 86, 98, 3, 4, 5, 6]]  # tilted 30 deg four ways, then upright
    T = make_pose(R, transform_points(T_R_X, p_X))
    sol = cell.robot.ik(T[:, None], tool=cell.tools["pointer"].T_F_TCP)
    q = np.array([sol.q[i][tuple(np.argwhere(ok)[rng.integers(ok.sum())])]
                  for i, ok in enumerate(sol.valid)])
    return Touches("external-tcp", q, None, None, roles, truth={}, tool="pointer",
                   noise=0.0), T_R_X


def test_an_external_tcp_carries_the_error_of_the_reference_tool():
    """Tool, then a fixed tool touched with it: every touch moves with the reference tool's
    error, so the external TCP's 1-sigma includes it (error / 1-sigma spread 0.8-1.25, fewer
    than 1 % of GOOD results more than 4 sigma off)."""
    _, fixed = cells()
    tool = fixed.tools["pointer"].T_F_TCP
    rng = np.random.default_rng(7)
    design = simulate(fixed, "tcp", noise=0.0, tool="pointer")
    touches, T_R_X = external_touches(fixed, rng)
    z, good, off = [], 0, 0
    for _ in range(EXTERNAL_TRIALS):
        t = cellcal.tcp(fixed, retouched(design, fixed, tool, rng, NOISE), "pointer",
                        sigma=NOISE)
        out = cellcal.external_tcp(t.cell, retouched(touches, fixed, tool, rng, NOISE),
                                   tool="pointer", sigma=NOISE)
        r = out.result
        z.append(z_scores(r.values["T_R_TCP"], T_R_X, r.sigma["T_R_TCP_position"],
                          r.sigma["T_R_TCP_rotation"]))
        if r.verdict.level == "good":
            good += 1
            off += bool(np.max(np.abs(z[-1])) > 4.0)
    assert out.inputs == ("tools.pointer",)
    spread = np.sqrt(np.mean(np.square(z), axis=0))
    assert np.all((spread > 0.8) & (spread < 1.25)), np.round(spread, 3)
    assert good >= 0.9 * EXTERNAL_TRIALS and off < 0.01 * good, (good, off)
