"""Scenes other than the cell's: calibration touches with the fitted geometry and magnified
residuals, a path with the arm at each point on a slider, a reach map, on synthetic data."""

import json

import numpy as np
import pytest
from cli_helpers import run
from view_helpers import (
    EXAMPLE,
    _chromium,
    assert_triad,
    figure_from_page,
    js_errors,
    moving_parts,
    render,
    traces,
    triads,
    xyz,
)

from robotcell import InputError, make_pose, rot_x, rot_z
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.cell import Cell
from robotcell.kinematics.transforms import transform_points
from robotcell.studies.reach import reach_map
from robotcell.view import (
    Arrows,
    PathMarks,
    Scene,
    Step,
    Triads,
    cell_scene,
    page,
    path_scene,
    scene_figure,
    write_html,
)
from robotcell.view.reach import reach_points, read_reach
from robotcell.view.shapes import (
    circle,
    circle_points,
    disk,
    line_through,
    magnification,
    residual_arrows,
    touches,
)


def turntable_touches(seed=0, outlier=3):
    """A point on a turntable touched at 8 angles (m), 0.05 mm noise, one touch off by 2 mm."""
    rng = np.random.default_rng(seed)
    T_R_B = make_pose(rot_z(0.7) @ rot_x(0.01), [2.1, 1.3, 0.4])
    theta = np.radians(np.arange(0, 360, 45))
    f = transform_points(T_R_B, np.column_stack([0.3 * np.cos(theta), 0.3 * np.sin(theta),
                                                 np.zeros(8)]))
    f = f + rng.normal(0, 5e-5, f.shape)
    f[outlier] += [0, 0, 0.002]
    return theta, f, T_R_B


def test_turntable_calibration_scene_shows_touches_circle_and_magnified_residuals():
    theta, f, _ = turntable_touches()
    res = calibrate_turntable(theta, f, sigma=5e-5)  # the touches' stated accuracy
    T, radius = res.values["T_R_B"], res.values["radius"]
    outliers = np.array([f"touch {lab} is an outlier" in " ".join(res.warnings)
                         for lab in res.labels])
    assert outliers.tolist() == [k == 3 for k in range(8)]
    factor = magnification(res.residuals, size=2 * radius)
    arrows = residual_arrows(res.points, res.residuals, factor, res.labels)
    scene = Scene("turntable", [*touches(res.points, res.labels, outliers),
                                circle("fitted circle", T, radius), arrows,
                                Triads("turntable B", T, ["B"], length=0.1)],
                  notes=[f"residual vectors magnified {factor:g} x"], frame="robot base R")
    fig = scene_figure(scene).to_plotly_json()
    # each touch, the outlier apart
    assert traces(fig, "touches")[0]["text"] == [str(k + 1) for k in range(8) if k != 3]
    out = traces(fig, "touches (outliers)")[0]
    assert out["text"] == ["4"] and out["marker"]["symbol"] == "x"
    np.testing.assert_allclose(xyz(out)[0], res.points[3] * 1e3, atol=1e-6)
    # the fitted circle goes through the point the fit predicts for each touch
    ring = xyz(traces(fig, "fitted circle")[0]) * 1e-3
    predicted = res.points - res.residuals
    local = transform_points(np.linalg.inv(T), predicted)
    np.testing.assert_allclose(np.hypot(local[:, 0], local[:, 1]), radius, atol=1e-12)
    np.testing.assert_allclose(local[:, 2], 0, atol=1e-12)
    gaps = np.linalg.norm(ring[:, None] - predicted[None], axis=-1).min(axis=0)
    assert gaps.max() < radius * np.pi / 72  # within one segment of the drawn polygon
    # residual vectors: from the predicted point, magnified by the stated factor
    # the outlier, left out of the fit, is 2.06 mm off it; drawn at most a tenth of the 600 mm
    # circle: 20 x (41 mm; 50 x would be 103 mm)
    longest = np.linalg.norm(res.residuals, axis=1).max()
    assert factor == 20.0 and 1.9e-3 < longest < 2.2e-3
    shafts = xyz(traces(fig, f"residuals x {factor:g}", "shafts")[0])
    np.testing.assert_allclose(shafts[0::3], predicted * 1e3, atol=1e-6)
    np.testing.assert_allclose(shafts[1::3], (predicted + factor * res.residuals) * 1e3, atol=1e-6)
    assert "magnified 20 x" in fig["layout"]["title"]["text"]
    assert_triad(triads(fig, "turntable B")["B"], T)
    assert fig["layout"]["scene"]["xaxis"]["title"]["text"] == "x in robot base R (mm)"


def test_calibration_scenes_of_each_procedure():
    from test_identification_positioner import GRID, NOISE, NOMINAL, _truth
    from test_report import frame_result

    from robotcell.calibration.tcp import calibrate_tool
    from robotcell.calibration.track import calibrate_track
    from robotcell.identification.positioner import calibrate_positioner
    from robotcell.view.calibration import calibration_scene

    def items(scene):
        return {i.name: i for i in scene.items}

    rng = np.random.default_rng(4)
    R = np.eye(4)
    # a TCP: its touches are one point, the reference tip; each is drawn at the tip of its
    # magnified residual, the robot base 1.1 m away is left out (a note says how far)
    flange = np.stack([make_pose(rot_z(0.9 * k) @ rot_x(2.6 + 0.1 * k), [0, 0, 0]) for k in range(6)])
    flange[:, :3, 3] = np.array([1.1, -0.2, 0.3]) - flange[:, :3, :3] @ [0.01, 0.005, 0.2]
    flange[:, :3, 3] += rng.normal(0, 5e-5, (6, 3))
    tcp = calibrate_tool(flange).to_json()
    scene = calibration_scene(tcp, "robot base R", [("robot base R", R)])
    got = items(scene)
    pivot = np.array(tcp["pivot_mm"]) * 1e-3
    res = np.array(tcp["residuals_xyz_mm"]) * 1e-3
    factor = float(next(n for n in scene.notes if "magnified" in n).split()[3])
    np.testing.assert_allclose(got["touches"].points, pivot + factor * res, atol=1e-12)
    np.testing.assert_allclose(got[f"residuals x {factor:g}"].origins, np.repeat([pivot], 6, 0),
                               atol=1e-12)
    assert "robot base R" not in got and "the origin of robot base R is 1.1" in scene.notes[0]
    assert not got["touches"].hover_xyz  # drawn where no touch was
    # a track with one unknown point: its line along the fitted direction, through every
    # fitted point
    e = np.linspace(0, 1.5, 6)
    f = np.array([1.5, 0.8, 0.3]) - np.outer(e, [0.9998, 0.02, 0.0]) + rng.normal(0, 5e-5, (6, 3))
    track = calibrate_track(e, f).to_json()
    line = items(calibration_scene(track, "robot base R", [("robot base R", R)]))["track line"]
    u = np.diff(line.points, axis=0)[0]
    u /= np.linalg.norm(u)
    assert abs(abs(u @ track["direction"]) - 1) < 1e-12
    fitted = (np.array(track["points_mm"]) - np.array(track["residuals_xyz_mm"])) * 1e-3
    off = (fitted - line.points[0]) - np.outer((fitted - line.points[0]) @ u, u)
    assert np.abs(off).max() < 1e-9
    # a tilt-rotate positioner: both axes and their common normal, as the result gives them
    ch, x = _truth(np.random.default_rng(31))
    f = ch.predict(x, GRID)[0][:, 0] + np.random.default_rng(2).normal(0, NOISE, (len(GRID), 3))
    pos = calibrate_positioner(GRID, f, nominal=NOMINAL, sigma=NOISE).result.to_json()
    got = items(calibration_scene(pos, "robot base R", [("robot base R", R),
                                                        ("turntable B", pos["matrix"])]))
    for name, point, axis in (("tilt axis", "tilt_point_mm", "tilt_axis"),
                              ("rotate axis (tilt at 0)", "rotate_point_mm", "rotate_axis")):
        ends = got[name].points
        d = np.cross(ends - np.array(pos[point]) * 1e-3, pos[axis])
        assert np.abs(d).max() < 1e-12, name
    np.testing.assert_allclose(np.linalg.norm(np.diff(got["common normal"].points, axis=0)) * 1e3,
                               pos["normal_length_mm"], rtol=1e-9)
    # a frame: its triad, each touch; a workpiece result holds no touched points
    frame = frame_result(outlier=True)
    T = np.array(frame["matrix"])
    scene = calibration_scene(frame, "robot base R", [("robot base R", R), ("workpiece W", T)])
    assert {"workpiece W", "touches", "touches (outliers)"} <= set(items(scene))
    lean = calibration_scene(frame, "robot base R", [("robot base R", R)], arrows=False)
    assert not any(isinstance(i, Arrows) for i in lean.items)
    dots = items(lean)["touches"]
    assert dots.values is not None and dots.value_title == "residual (mm)"
    work = {"procedure": "workpiece", "residuals_xyz_mm": frame["residuals_xyz_mm"],
            "labels": frame["labels"], "warnings": []}
    scene = calibration_scene(work, "turntable B", [("turntable B", R), ("workpiece W", T)])
    assert set(items(scene)) == {"turntable B", "workpiece W"}
    assert "holds no touched points" in scene.notes[0]


def test_a_scene_too_large_for_the_page_is_drawn_lighter_or_left_out():
    from robotcell.view.plot import embed, embed_within

    rng = np.random.default_rng(5)
    p = rng.uniform(-1, 1, (300, 3))
    r = rng.normal(0, 1e-4, (300, 3))
    full = Scene("many", [*touches(p, residuals=r, show_labels=False),
                          residual_arrows(p, r, 100.0, hover=False)])
    dots = Scene("many", touches(p, residuals=r, show_labels=False, color_by_residual=True))
    size = len(embed(full).encode())
    text, drawn = embed_within([full, dots], size)
    assert drawn is full and len(text.encode()) == size
    text, drawn = embed_within([full, dots], size - 1)  # no hover texts, no arrow heads
    assert drawn.notes[-1] == "hover texts and arrow heads left out, to keep the page under 5 MB"
    assert len(text.encode()) < size and drawn.items[0].hover is None
    heads = traces(figure_from_page(text), "residuals x 100", "heads")[0]
    assert drawn.items[-1].head == 0 and not heads.get("x")
    light = len(text.encode())
    text, drawn = embed_within([full, dots], light - 1)  # the lighter scene: no arrows
    assert drawn.items[0].values is not None and len(text.encode()) < light
    assert embed_within([full, dots], 1_000_000) == ("", None)


def test_magnification_states_a_round_factor():
    r = np.array([[0.0, 0.0, 3e-4], [1e-4, 0, 0]])  # longest 0.3 mm
    assert magnification(r, size=1.0) == 200.0  # 0.1 m / 0.3 mm = 333 -> 200
    assert magnification(r, size=0.45) == 100.0  # 150 -> 100
    assert magnification(r, size=0.0015) == 1.0  # never drawn shorter than it is
    assert magnification(np.zeros((2, 3)), size=1.0) == 1.0
    assert magnification(r, size=0.015) == 5.0
    with pytest.raises(InputError, match="size must be a length > 0"):
        magnification(r, size=0.0)


def test_shapes():
    T = make_pose(rot_x(0.3), [1.0, 2.0, 3.0])
    p = circle_points(T, 0.25, 12)
    assert p.shape == (13, 3) and np.allclose(p[0], p[-1])
    local = transform_points(np.linalg.inv(T), p)
    np.testing.assert_allclose(np.linalg.norm(local[:, :2], axis=1), 0.25, atol=1e-12)
    np.testing.assert_allclose(local[:, 2], 0, atol=1e-12)
    plate = disk("plate", T, 0.25, n=12)
    assert plate.faces.shape == (12, 3) and plate.vertices.shape == (13, 3)
    # a fitted line spans the projections of its points, 10 % longer at each end
    pts = np.array([[0.0, 0, 0], [1.0, 0.1, 0], [3.0, -0.1, 0]])
    line = line_through("track", [0, 0, 0], [2, 0, 0], pts)
    np.testing.assert_allclose(line.points, [[-0.3, 0, 0], [3.3, 0, 0]], atol=1e-12)
    with pytest.raises(InputError, match="line direction must not be zero"):
        line_through("track", [0, 0, 0], [0, 0, 0], pts)
    with pytest.raises(InputError, match="radius must be a length > 0"):
        circle("c", T, -1.0)
    with pytest.raises(InputError, match="touches: 2 labels for 3 points"):
        touches(pts, labels=["a", "b"])
    with pytest.raises(InputError, match=r"outliers must be 3 booleans, got shape \(2,\)"):
        touches(pts, outliers=[True, False])
    with pytest.raises(InputError, match="residuals: 2 vectors for 3 touches"):
        residual_arrows(pts, pts[:2], 10.0)
    with pytest.raises(InputError, match="factor must be a length > 0"):
        residual_arrows(pts, pts, 0.0)


def test_scene_items_refuse_bad_geometry():
    from robotcell.view import Arrows, Lines, Mesh, Points

    with pytest.raises(InputError, match="links contains NaN"):
        Lines("links", [[0, 0, 0], [np.nan, 1, 1]])  # a break is a whole row of NaN
    Lines("links", [[0, 0, 0], [np.nan] * 3, [1, 1, 1]])
    with pytest.raises(InputError, match="map: values must be 2 finite numbers"):
        Points("map", np.zeros((2, 3)), values=[0.5])
    with pytest.raises(InputError, match="axes: 1 origins for 2 vectors"):
        Arrows("axes", np.zeros((1, 3)), np.ones((2, 3)))
    with pytest.raises(InputError, match="plate: a face refers to a vertex that does not exist"):
        Mesh("plate", np.zeros((3, 3)), [[0, 1, 3]])
    with pytest.raises(InputError, match="frames: 1 texts for 2 elements"):
        Triads("frames", np.stack([np.eye(4)] * 2), ["a"])
    with pytest.raises(InputError, match="every step of a scene must hold the same kinds"):
        Scene("s", steps=[Step("1", (Lines("a", np.zeros((2, 3))),)),
                          Step("2", (Points("a", np.zeros((2, 3))),))])


def seam(cell, n=12):
    """A synthetic path: the torch along a line over the part, solved by the cell's IK."""
    from robotcell import rot_y

    x = np.linspace(-0.1, 0.1, n)
    T = make_pose(rot_y(np.pi), np.column_stack([x, np.zeros(n), np.full(n, 0.01)]))
    return cell.ik_path(T, frame="part", table=np.radians(150), tool="torch")


def chain_vertices(cell, q, e, th):
    """The vertices of the robot's links (mm) at each configuration, without those that
    coincide with the one before at every configuration (as the path's view drops them)."""
    from robotcell.cell.kinematics import robot_pose
    from robotcell.view.arm import chain_pose

    v = np.stack([chain_pose(cell.robot, qi, robot_pose(cell, ei)).vertices
                  for qi, ei in zip(q, e)]) * 1e3
    keep = np.concatenate([[True], ~np.all(np.isclose(v[:, 1:], v[:, :-1], rtol=0, atol=1e-6),
                                           axis=(0, 2))])
    return v[:, keep]


def assert_triad_line(drawn, T, length_mm, tol):
    """A triad drawn as one polyline (origin, X tip, gap, origin, Y tip, gap, origin, Z tip) is
    the pose ``T`` (m) to ``tol`` mm."""
    o = T[:3, 3] * 1e3
    np.testing.assert_allclose(drawn[[0, 3, 6]], [o] * 3, rtol=0, atol=tol)
    np.testing.assert_allclose(drawn[[1, 4, 7]], o + length_mm * T[:3, :3].T, rtol=0, atol=tol)
    assert np.all(np.isnan(drawn[[2, 5]]))


def test_path_scene_puts_the_arm_at_each_point_where_fk_does():
    from robotcell.view.cellscene import frame_size

    cell = Cell.load(EXAMPLE)
    path = seam(cell)
    n = len(path.q)
    table = np.radians(150 + np.linspace(0, 20, n))  # the table turns along the path
    track = path.track + np.linspace(0, 0.3, n)  # and the track moves
    bad = np.zeros(n, bool)
    bad[4] = True
    reasons = [""] * n
    reasons[4] = "A5 within 1 deg of its limit"
    scene = path_scene(cell, path.q, track, table, tool="torch",
                       marks=PathMarks(bad=bad, reasons=reasons))
    data = figure_from_page(page(scene_figure(scene)))
    assert len(data["frames"]) == n
    assert [s["label"] for s in data["layout"]["sliders"][0]["steps"]] == [str(k + 1) for k in range(n)]
    # the marked point, with its reason; the path through every TCP (0.01 mm in the page)
    mark = traces(data, "bad points")[0]
    assert mark["hovertext"] == ["<b>point 5</b>: A5 within 1 deg of its limit"]
    tcp = cell.fk(path.q, track, table, tool="torch")
    np.testing.assert_allclose(xyz(mark)[0], tcp[4, :3, 3] * 1e3, rtol=0, atol=0.005)
    np.testing.assert_allclose(xyz(traces(data, "TCP path")[0]), tcp[:, :3, 3] * 1e3, rtol=0,
                               atol=0.005)
    # at each step the links, the tool, the TCP and the frame on the table where the cell's FK
    # puts them, to the 0.01 mm the page holds
    links = chain_vertices(cell, path.q, track, table)
    length = frame_size(cell.robot) * 1e3
    flange = cell.fk(path.q, track, table, tool=np.eye(4))
    for k in range(n):
        parts = moving_parts(data, k)
        np.testing.assert_allclose(parts["robot kuka_kr16: links"], links[k], rtol=0, atol=0.005)
        np.testing.assert_allclose(parts["tool"], [flange[k, :3, 3] * 1e3, tcp[k, :3, 3] * 1e3],
                                   rtol=0, atol=0.005)
        assert_triad_line(parts["TCP"], tcp[k], length, 0.005)
        assert_triad_line(parts["frames: part"], cell.frame_pose("part", track[k], table[k]),
                          length, 0.005)
    # what does not move is drawn once, outside the steps: the world axes, the fixture, the
    # turntable's plate (a disk turned about its axis is the same disk); what moves is one
    # polyline and the labels of the frames on the table
    moving = {data["data"][i]["meta"]["item"] for i in data["frames"][0]["traces"]}
    assert moving == {"cell at the point", "moving frames"}
    still = {t["meta"]["item"] for t in data["data"]}
    assert {"world", "frames: fixture", "turntable DKP_400_01: plate"} <= still
    assert triads(data, "frames: fixture")["fixture"]
    # each step is a frame's vertices only: a path of 300 points fits in 5 MB with plotly.js
    frame = json.dumps(data["frames"][1], separators=(",", ":"))
    assert '"type"' not in frame and len(frame) < 900


def test_path_of_hundreds_of_points_fits_in_a_page(tmp_path):
    # the track moving along 320 points, the arm at each: under 5 MB (docs/view.md)
    cell = Cell.load(EXAMPLE)
    path = seam(cell, n=320)
    track = path.track + np.linspace(0, 0.5, 320)
    text = page(path_scene(cell, path.q, track, np.radians(150), tool="torch"))
    assert len(text.encode()) < 5_000_000
    data = figure_from_page(text)
    assert len(data["frames"]) == 320 and len(data["layout"]["sliders"][0]["steps"]) == 320
    # the slider's steps name their frame only; the page does not play on opening
    assert data["layout"]["sliders"][0]["steps"][7]["args"] == [["7"], {"mode": "immediate"}]
    assert "Plotly.animate" not in text[text.index("Plotly.newPlot("):]
    # every 4th point: the whole path, the arm at 80 points, and the page says so
    scene = path_scene(cell, path.q, track, np.radians(150), tool="torch", every=4)
    assert [s.label for s in scene.steps] == [str(k + 1) for k in range(0, 320, 4)]
    assert len(scene.items[[i.name for i in scene.items].index("TCP path")].points) == 320
    assert "the arm is drawn at every 4th of the 320 points" in " ".join(scene.notes)
    with pytest.raises(InputError, match="every must be a whole number >= 1, got 0"):
        path_scene(cell, path.q, every=0)


def test_browser_plays_the_path(tmp_path):
    # the animation frames, the slider and the play button load with no JavaScript error
    exe = _chromium()
    cell = Cell.load(EXAMPLE)
    path = seam(cell, n=6)
    out = write_html(path_scene(cell, path.q, path.track, np.radians(150), tool="torch"),
                     tmp_path / "path.html")
    dom, console, _ = render(exe, out, tmp_path, screenshot=False)
    assert 'data-scene="rendered"' in dom and "slider" in dom
    assert not js_errors(console), console
    # a guard: the check sees an error thrown by a page
    broken = tmp_path / "broken.html"
    broken.write_text("<html><body><script>undefined_function();</script></body></html>")
    _, console, _ = render(exe, broken, tmp_path, screenshot=False)
    assert any("Uncaught ReferenceError" in m for m in js_errors(console)), console


def test_path_scene_with_points_without_joint_values():
    cell = Cell.load(EXAMPLE)
    path = seam(cell, n=5)
    q = path.q.copy()
    q[2] = np.nan  # an unreachable target: no arm there
    where = cell.fk(path.q, path.track, np.radians(150), tool="torch")[:, :3, 3]
    bad = np.arange(5) == 2
    reasons = ["", "", "unreachable: 40 mm beyond the arm's reach", "", ""]
    # without its position it cannot be marked: a note names it
    scene = path_scene(cell, q, path.track, np.radians(150), tool="torch",
                       marks=PathMarks(bad=bad, reasons=reasons))
    assert "bad points" not in [i.name for i in scene.items]
    assert "not drawn, no position: point 3: unreachable: 40 mm beyond the arm's reach" in scene.notes
    scene = path_scene(cell, q, path.track, np.radians(150), tool="torch",
                       marks=PathMarks(bad=bad, reasons=reasons, points=where))
    fig = scene_figure(scene).to_plotly_json()
    np.testing.assert_allclose(xyz(traces(fig, "bad points")[0])[0], where[2] * 1e3, atol=0.005)
    # its step shows the arm of the point before it
    np.testing.assert_array_equal(scene.steps[2].items[0].points, scene.steps[1].items[0].points)
    # a tool per point, unknown (NaN) at one: no TCP drawn there, the arm is
    tools = np.repeat(cell.tools["torch"].T_F_TCP[None], 5, axis=0)
    tools[3] = np.nan
    scene = path_scene(cell, path.q, path.track, np.radians(150), tool=tools)
    parts = {name: (a, b) for name, a, b in scene.steps[3].items[0].parts}
    a, b = parts["TCP"]
    assert np.all(np.isnan(scene.steps[3].items[0].points[a:b]))
    assert np.all(np.isfinite(scene.steps[2].items[0].points[a:b][[0, 1]]))
    with pytest.raises(InputError, match=r"q must have shape \(N, 6\)"):
        path_scene(cell, q[:, :5])
    with pytest.raises(InputError, match="no point of the path has joint values"):
        path_scene(cell, np.full((2, 6), np.nan))
    with pytest.raises(InputError, match=r"labels, bad, reasons and hover need one entry per "
                                         r"point \(5\)"):
        path_scene(cell, path.q, path.track, marks=PathMarks(labels=["a"]))
    with pytest.raises(InputError, match=r"tool must have shape \(4, 4\) or \(5, 4, 4\)"):
        path_scene(cell, path.q, path.track, tool=tools[:2])
    with pytest.raises(InputError, match=r"points must have shape \(5, 3\)"):
        path_scene(cell, path.q, path.track, marks=PathMarks(points=where[:2]))


def test_reach_map_read_back_from_the_csv_of_reach(tmp_path, capsys):
    seam_csv = EXAMPLE.with_name("seam_part.csv")
    out = tmp_path / "reach.csv"
    code, _, err = run(capsys, "reach", "--cell", EXAMPLE, seam_csv, "--frame", "part", "--tool",
                       "torch", "-o", out)
    assert code == 0, err
    cell = Cell.load(EXAMPLE)
    table = read_reach(out, cell)
    # the same map in Python: each reachable target at the TCP its axis values give
    from robotcell.io.targets import read_targets

    T, th = (t := read_targets(seam_csv)).poses, t.table
    rm = reach_map(cell, T, frame="part", tool="torch", table=th)
    assert np.array_equal(table.reachable, rm.reachable) and table.reachable.all()
    mine = reach_points(cell, table, tool="torch")
    np.testing.assert_allclose(mine.points, reach_points(cell, rm, tool="torch").points,
                               atol=2e-9)  # the CSV has 6 decimals of mm and deg
    target = cell.frame_pose("part", 0.0, th) @ T
    np.testing.assert_allclose(mine.points, target[:, :3, 3], atol=2e-8)
    np.testing.assert_allclose(mine.values, rm.score, atol=1e-6)
    # in the view: coloured by score, and a target the map could not reach is counted
    rows = out.read_text().splitlines()
    cells = rows[3].split(",")
    cells[1:3] = ["false" if cells[1] == "true" else "0", "0.000000"]  # as reach writes it
    cells[3:13] = ["nan"] * 10
    rows[3] = ",".join(cells)
    out.write_text("\n".join(rows) + "\n")
    scene = cell_scene(cell, reach=read_reach(out, cell), tool="torch")
    assert scene.notes[-1] == ("reach map: each reachable target at its TCP in the world; 1 "
                               "unreachable target(s) not drawn (no axis values)")
    fig = scene_figure(scene).to_plotly_json()
    points = traces(fig, "reach map")[0]
    assert len(points["x"]) == len(T) - 1 and points["marker"]["cmax"] == 1
    assert points["hovertext"][2].startswith("<b>target 3</b>: score")
    # the command draws it
    code, _, err = run(capsys, "view", EXAMPLE, "--reach", out, "--tool", "torch", "-o",
                       tmp_path / "reach.html")
    assert code == 0, err
    text = (tmp_path / "reach.html").read_text(encoding="utf-8")
    assert len(traces(figure_from_page(text), "reach map")[0]["x"]) == len(T) - 1


def test_reach_csv_errors(tmp_path):
    cell = Cell.load(EXAMPLE)
    bad = tmp_path / "bad.csv"
    head = "target,reachable,score,track,table,a1,a2,a3,a4,a5,a6\n"
    for row, message in (("0,2,0.5,0,0,0,0,0,0,0,0",
                          "line 2: 'reachable' must be true or false \\(or 1 or 0\\), got '2.0'"),
                         ("0,yes,0.5,0,0,0,0,0,0,0,0", "line 2: 'reachable' must be true or false"),
                         ("0,1,1.5,0,0,0,0,0,0,0,0", r"line 2: 'score' must be within \[0, 1\]"),
                         ("0,1,0.5,0,0,nan,0,0,0,0,0",
                          ("line 2: a reachable target needs finite values of track, table and "
                           "a1..a6"))):
        bad.write_text(head + row + "\n")
        with pytest.raises(InputError, match=message):
            read_reach(bad, cell)
    bad.write_text("target,reachable,score\n0,1,0.5\n")
    with pytest.raises(InputError, match="missing column"):
        read_reach(bad, cell)
    bad.write_text("target,score\n0,0.5\n")
    with pytest.raises(InputError, match="missing column reachable"):
        read_reach(bad, cell)
    # true/false, as reach writes the column, and 1/0
    for yes, no in (("true", "false"), ("1", "0")):
        bad.write_text(f"{head}0,{yes},0.5,0,0,0,-90,90,0,0,0\n1,{no},0,nan,nan,nan,nan,nan,"
                       "nan,nan,nan\n")
        assert read_reach(bad, cell).reachable.tolist() == [True, False]


def test_arrow_heads_fit_their_arrows():
    from robotcell.view import Arrows

    arrows = Arrows("residuals", np.zeros((3, 3)), [[0.1, 0, 0], [0, 0.01, 0], [0, 0, 0]])
    fig = scene_figure(Scene("arrows", [arrows])).to_plotly_json()
    heads = traces(fig, "residuals", "heads")[0]
    # one size (a quarter of the longest), at most half a short arrow, none on a zero arrow
    np.testing.assert_allclose(np.column_stack([heads["u"], heads["v"], heads["w"]]),
                               [[25.0, 0, 0], [0, 5.0, 0]], atol=1e-9)
    np.testing.assert_allclose(xyz(heads), [[100.0, 0, 0], [0, 10.0, 0]], atol=1e-9)
