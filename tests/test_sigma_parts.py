"""Every reported 1-sigma says what it is relative to: its own touches apart from what it
inherits, and an assumed (not recorded) upstream accuracy labelled as assumed."""

import json

import numpy as np
import pytest
from cli_helpers import run

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


def test_a_result_with_its_own_touches_only_has_its_own_part_only():
    cell = Cell.load(EXAMPLE)
    r = cellcal.tcp(cell, simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
                    .to_table(), "pointer", sigma=NOISE).result
    data = r.to_json()
    assert {k: set(p) for k, p in data["sigma_parts"].items()} == {
        "tcp": {"relative_to", "unit", "own"}, "pivot": {"relative_to", "unit", "own"},
        "T_F_TCP": {"relative_to", "own"}}
    np.testing.assert_allclose(data["sigma_parts"]["T_F_TCP"]["own"]["position_mm"],
                               data["sigma"]["T_F_TCP_position_mm"])
    text = r.summary()
    assert "ASSUMED" not in text and "its parts" not in text
    assert "the 1-sigma above is relative to the flange, from its own touches only" in text


def track_touches(cell, tool, seed):
    touches = simulate(cell, "track", noise=NOISE, seed=seed, tool=tool)
    return touches.to_table(), touches.keywords()


def test_a_track_touched_with_a_nominal_tool_labels_the_assumed_part_of_its_scale():
    """The example's tool 'pointer' records no uncertainty: the track's scale and direction
    inherit its assumed 1 mm and 0.5 deg; report, JSON and verdict label that part ASSUMED and
    give the part its own touches determine."""
    cell = Cell.load(EXAMPLE)
    table, kw = track_touches(cell, "pointer", 3)
    r = cellcal.track(cell, table, tool="pointer", sigma=NOISE, **kw).result
    data = r.to_json()
    scale = data["sigma_parts"]["scale"]
    assert scale["relative_to"] == "R" and scale["unit"] == ""
    assert scale["assumed"]["sources"] == ["tools.pointer"] and "recorded" not in scale
    assert np.hypot(scale["own"]["sigma"], scale["assumed"]["sigma"]) == pytest.approx(
        data["sigma"]["scale"], rel=1e-6)
    assert scale["assumed"]["sigma"] > 0 and scale["own"]["sigma"] > 0
    direction = data["sigma_parts"]["direction"]
    np.testing.assert_allclose(np.hypot(direction["own"]["sigma"], direction["assumed"]["sigma"]),
                               data["sigma"]["direction"], rtol=1e-6, atol=1e-12)
    text = r.summary()
    scale_at = text.index("  scale:")
    assert ("from its own touches and inherited errors (ASSUMED))" in text[scale_at:]
            and "(ASSUMED accuracy) [tools.pointer]" in text[scale_at:])
    assert any(s.startswith("scale: up to ") and "ASSUMED (tools.pointer: no recorded "
               "uncertainty); its own touches determine it to " in s for s in r.verdict.reasons)


def test_a_track_touched_with_a_calibrated_tool_has_a_recorded_part_and_no_assumed_one():
    cell = Cell.load(EXAMPLE)
    cell = cellcal.tcp(cell, simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
                       .to_table(), "pointer", sigma=NOISE).cell
    table, kw = track_touches(cell, "pointer", 3)
    r = cellcal.track(cell, table, tool="pointer", sigma=NOISE, **kw).result
    parts = r.to_json()["sigma_parts"]
    assert all("assumed" not in p and set(p) >= {"own", "recorded"} for p in parts.values())
    assert not any("ASSUMED" in s for s in r.verdict.reasons)


def test_a_turntable_beside_an_uncalibrated_track_labels_the_assumed_part_of_its_tilt():
    """The table's tilt from the world's Z inherits the track's assumed 0.5 deg, far above what
    its own touches determine; its radius, a length on the table, inherits little."""
    cell = Cell.load(EXAMPLE)
    tool = cellcal.tcp(cell, simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
                       .to_table(), "pointer", sigma=NOISE).cell
    touches = simulate(tool, "turntable", noise=NOISE, seed=2, tool="pointer")
    r = cellcal.turntable(tool, touches.to_table(), tool="pointer", sigma=NOISE,
                          **touches.keywords()).result
    parts = r.to_json()["sigma_parts"]
    tilt = parts["tilt"]
    assert tilt["relative_to"] == "world" and tilt["unit"] == "deg"
    assert tilt["assumed"]["sources"] == ["track"] and tilt["assumed"]["sigma"] > 0.3
    assert tilt["own"]["sigma"] < 0.1
    assert parts["radius"]["own"]["sigma"] < 0.1
    assert any(s.startswith("tilt: up to ") and " deg of its 1-sigma is ASSUMED (track" in s
               for s in r.verdict.reasons)


def test_calibrate_cell_says_what_each_items_sigma_is_relative_to(tmp_path, capsys):
    cell = Cell.load(EXAMPLE)
    touches = simulate(cell, "tcp", noise=NOISE, seed=1, tool="pointer")
    touches.write_csv(tmp_path / "tcp.csv")
    cell = cellcal.tcp(cell, str(tmp_path / "tcp.csv"), "pointer", sigma=NOISE).cell
    touches = simulate(cell, "turntable", noise=NOISE, seed=2, tool="pointer")
    touches.write_csv(tmp_path / "table.csv")
    cell = cellcal.turntable(cell, str(tmp_path / "table.csv"), tool="pointer", sigma=NOISE,
                             **touches.keywords()).cell
    cell.save(tmp_path / "cell.yaml")
    cell.save(tmp_path / "copy.yaml")
    code, out, err = run(capsys, "calibrate", "cell", "--cell", tmp_path / "cell.yaml", "--json")
    assert code == 0, err
    items = {i["item"]: i["sigma_relative_to"] for i in json.loads(out)["items"]}
    assert items == {"tools.pointer": "F", "turntable": "world"}
    code, out, err = run(capsys, "calibrate", "cell", "--cell", tmp_path / "copy.yaml")
    assert code == 0, err
    own = "from its own touches, with the cell's other calibrations, and the errors it inherits"
    assert f"  tools.pointer: relative to the flange, {own}" in out
    assert f"  turntable: relative to frame 'world', {own}" in out


def test_an_assumed_part_under_1_percent_of_the_own_part_is_no_reason_of_the_verdict():
    from robotcell.calibration.verdict import _assumed_parts
    parts = {"radius": {"unit": "mm", "assumed": {"sigma": [9e-9], "sources": ["track"]},
                        "own": {"sigma": [0.04]}},
             "tilt": {"unit": "deg", "assumed": {"sigma": [0.7], "sources": ["track"]},
                      "own": {"sigma": [0.016]}}}
    reasons = _assumed_parts({"sigma_parts": parts})
    assert len(reasons) == 1 and reasons[0].startswith("tilt: up to 0.7 deg of its 1-sigma is "
                                                        "ASSUMED (track: no recorded uncertainty)")
