"""Every reported 1-sigma says what it is relative to: its own touches apart from what it
inherits, and an assumed (not recorded) upstream accuracy labelled as assumed."""

import numpy as np

from robotcell.cell import Cell
from robotcell.cell import calibrate as cellcal
from robotcell.studies.simulate import simulate

EXAMPLE = "examples/cell_kr16_track_turntable.yaml"
NOISE = 1e-4


def test_a_turntable_beside_an_uncalibrated_track_reports_its_measured_sigma_apart():
    """The example track has no recorded uncertainty: the table's world position inherits its
    nominal 0.5 deg (about 14 mm), while the table relative to the robot (its own touches and
    the calibrated tool) is known to about 0.1 mm; report, JSON and verdict say which is which."""
    cell = Cell.load(EXAMPLE)
    tool = cellcal.tcp(cell, simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
                       .to_table(), "pointer", sigma=NOISE).cell
    touches = simulate(tool, "turntable", noise=NOISE, seed=2, tool="pointer")
    r = cellcal.turntable(tool, touches.to_table(), tool="pointer", sigma=NOISE,
                          **touches.keywords()).result
    parts = r.to_json()["sigma_parts"]["T_world_B"]
    assert parts["relative_to"] == "world" and parts["assumed"]["sources"] == ["track"]
    measured = np.hypot(parts["own"]["position_mm"], parts["recorded"]["position_mm"])
    assert np.all((measured > 0.03) & (measured < 0.3)), measured
    assert np.max(parts["assumed"]["position_mm"]) > 10.0
    assert np.max(r.sigma["T_world_B_position"]) * 1e3 > 10.0  # the total keeps the datum
    text = r.summary()
    assert "relative to frame 'world'" in text and "(ASSUMED accuracy) [track]" in text
    assert "its own touches, relative to what touched" in text
    v = r.verdict
    assert v.level == "good" and any("ASSUMED (track: no recorded uncertainty)" in s
                                     for s in v.reasons)


def test_a_result_with_its_own_touches_only_has_no_parts():
    cell = Cell.load(EXAMPLE)
    r = cellcal.tcp(cell, simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
                    .to_table(), "pointer", sigma=NOISE).result
    assert "sigma_parts" not in r.to_json() and "ASSUMED" not in r.summary()
