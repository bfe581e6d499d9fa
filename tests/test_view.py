"""The 3D view of a cell: every frame where the cell's kinematics put it, one self-contained page
that a real headless browser renders, and the command's refusals."""

import re

import numpy as np
import pytest
from cli_helpers import run
from view_helpers import (
    EXAMPLE,
    JOINTS,
    TABLE,
    TRACK,
    _chromium,
    assert_triad,
    figure_from_page,
    js_errors,
    render,
    traces,
    triads,
    xyz,
)

from robotcell import InputError, load_robot
from robotcell.cell import Cell
from robotcell.view import cell_figure, cell_scene, page, write_html
from robotcell.view.arm import chain_pose
from robotcell.view.plot import DECIMALS, RENDERED

POSITIONER = EXAMPLE.with_name("cell_kr16_positioner.yaml")
#: The page stays under this size (bytes): plotly.js inlined is about 4.8 MB of it.
MAX_PAGE = 5_000_000


def random_state(cell, seed):
    """Seeded joints within the limits (revolute axes within +-170 deg), track, table values."""
    rng = np.random.default_rng(seed)
    r = cell.robot
    q = rng.uniform(np.maximum(r.lower, -3.0), np.minimum(r.upper, 3.0))
    e = rng.uniform(cell.track.lower, cell.track.upper) if cell.track is not None else 0.0
    pos = cell.turntable
    v = rng.uniform(np.maximum(pos.lower, -3.0), np.minimum(pos.upper, 3.0))
    return q, e, v if pos.n_axes > 1 else float(v)


def expected_frames(cell, q, e, v):
    """Every frame the view must draw, from the cell's own functions: (item, label) -> T (m)."""
    T_world_R = cell.frame_pose("robot", e)
    dh = T_world_R @ cell.robot.frames(q)
    flange = cell.fk(q, e, v, tool=np.eye(4))
    out = {("world", "world"): np.eye(4), ("robot R", "robot R"): T_world_R,
           (f"robot {cell.robot.name}: flange F", "flange F"): flange}
    out.update({(f"robot {cell.robot.name}: DH frames", str(i)): T for i, T in enumerate(dh)})
    out.update({("tools", name): cell.fk(q, e, v, tool=name) for name in cell.tools})
    out.update({("frames", name): cell.frame_pose(name, e, v) for name in cell.frames})
    if cell.track is not None:
        out[("track L", "track L")] = cell.frame_pose("track")
    pos = cell.turntable
    kind = "positioner" if pos.n_axes > 1 else "turntable"
    root = cell.frame_pose("turntable", e, v)
    out[("turntable B" if kind == "turntable" else "positioner root",) * 2] = root
    chain = root @ pos.chain.with_base(np.eye(4)).frames(np.atleast_1d(v))
    out.update({(f"{kind} {pos.name}: DH frames", str(i)): T for i, T in enumerate(chain)})
    carried = next(n for n, f in cell.frames.items() if f.parent == "turntable")
    plate = cell.frame_pose(carried, e, v) @ np.linalg.inv(cell.frames[carried].pose)
    out[(f"{kind} {pos.name}: plate P", "plate P")] = plate
    return out


def check_every_frame(fig, cell, q, e, v):
    frames = expected_frames(cell, q, e, v)
    read = {}
    for item in {i for i, _ in frames}:
        read.update({(item, label): f for label, f in triads(fig, item).items()})
    assert set(read) == set(frames)
    for key, T in frames.items():
        assert_triad(read[key], T)
    # The links pass through every DH origin and end at the flange, in order.
    links = xyz(traces(fig, f"robot {cell.robot.name}: links")[0])
    dh = [T for (item, _), T in frames.items() if item.endswith("DH frames") and "robot" in item]
    np.testing.assert_allclose(links[:-1:2], np.array(dh)[:, :3, 3] * 1e3, rtol=0, atol=1e-6)
    np.testing.assert_allclose(links[-1], frames[(f"robot {cell.robot.name}: flange F",
                                                  "flange F")][:3, 3] * 1e3, rtol=0, atol=1e-6)


@pytest.mark.parametrize("path,seed", [(EXAMPLE, 0), (EXAMPLE, 1), (POSITIONER, 2)])
def test_the_figure_puts_every_frame_where_the_cell_does(path, seed):
    cell = Cell.load(path)
    q, e, v = random_state(cell, seed)
    fig = cell_figure(cell, q, e, v).to_plotly_json()
    check_every_frame(fig, cell, q, e, v)


def test_the_page_holds_the_same_scene(tmp_path):
    cell = Cell.load(EXAMPLE)
    q, e, v = random_state(cell, 3)
    written = write_html(cell_figure(cell, q, e, v), tmp_path / "cell.html")
    text = written.read_text(encoding="utf-8")
    check_every_frame(figure_from_page(text), cell, q, e, v)
    # One file: plotly.js inlined, no script or style from elsewhere, under the size stated.
    assert written.stat().st_size < MAX_PAGE
    assert re.findall(r"<script[^>]*>", text) == ["<script>"] * 3 and "<link" not in text
    assert text.count("Plotly.newPlot(") == 1 and len(text) > 4_000_000
    # Coordinates are written to 1e-6 mm, not to the 17 digits of a double.
    numbers = re.findall(r"-?\d+\.(\d+)", text[text.index("Plotly.newPlot("):])
    assert max(len(d) for d in numbers) <= DECIMALS


def test_write_cell_view_is_the_view_command_as_one_call(tmp_path):
    from robotcell.view import write_cell_view

    cell = Cell.load(EXAMPLE)
    q, e, v = random_state(cell, 4)
    written = write_cell_view(cell, tmp_path / "cell.html", q, e, v)
    text = written.read_text(encoding="utf-8")
    check_every_frame(figure_from_page(text), cell, q, e, v)
    assert f"<title>{cell.name}: robotcell view</title>" in text
    with pytest.raises(InputError, match="nowhere.csv"):
        write_cell_view(cell, tmp_path / "r.html", reach=tmp_path / "nowhere.csv")
    assert not (tmp_path / "r.html").exists()


def test_hover_gives_each_frame_in_the_cell_convention():
    cell = Cell.load(EXAMPLE)
    fig = cell_figure(cell, np.radians([0, -90, 90, 0, 0, 0]), 1.5, np.radians(30)).to_plotly_json()
    hover = dict(zip(traces(fig, "tools", "origins")[0]["text"],
                     traces(fig, "tools", "origins")[0]["hovertext"]))
    # the torch: T_F_TCP as the cell file holds it, and its pose in the world (x y z mm, a b c deg)
    assert "T_F_TCP (cell file): x 312.500 y -1.200 z 95.000 mm<br>a 0.000 b 45.000 c 0.000 deg" \
        in hover["torch"]
    T = cell.fk(np.radians([0, -90, 90, 0, 0, 0]), 1.5, np.radians(30), tool="torch")
    from robotcell import pose_to_vendor

    x, y, z, a, b, c = pose_to_vendor(T, "kuka")
    assert f"in the world: x {x:.3f} y {y:.3f} z {z:.3f} mm<br>a {a:.3f} b {b:.3f} c {c:.3f} deg" \
        in hover["torch"]
    # each joint axis names its value and limits
    axes = traces(fig, "robot kuka_kr16: joint axes", "shafts")[0]["hovertext"]
    assert "<b>A2</b> turns about this arrow: -90.000 deg<br>limits [-155, 35] deg" in axes


def test_scene_defaults_and_notes():
    cell = Cell.load(EXAMPLE)
    scene = cell_scene(cell)  # the robot model's home configuration
    assert scene.title == "kr16_track_turntable: axes 0, -90, 90, 0, 0, 0 deg; track 0 mm; table 0 deg"
    assert "lengths in mm" in scene.notes[0]
    # drawn outside the limits, but said so
    scene = cell_scene(cell, np.radians([0, 60, 90, 0, 0, 0]))
    assert scene.notes[-1] == "outside their limits: A2"
    with pytest.raises(InputError, match=r"joints: kuka_kr16 has 6 axes, got shape \(5,\)"):
        cell_scene(cell, np.zeros(5))
    with pytest.raises(InputError, match="joints contains NaN"):
        cell_scene(cell, [0, 0, np.nan, 0, 0, 0])
    with pytest.raises(InputError, match=r"track: give one track position \(m\), got shape \(2,\)"):
        cell_scene(cell, track=[1.0, 2.0])
    # a prismatic axis in mm (the Stanford arm's third)
    from robotcell.view.cellscene import axes_text

    assert axes_text(load_robot("stanford_arm"), [0.1, 0, 0.25, 0, 0, 0]) == (
        "5.73 deg, 0 deg, 250.000 mm, 0 deg, 0 deg, 0 deg")
    bare = Cell(robot=cell.robot, robot_model="kuka_kr16")
    with pytest.raises(InputError, match="the cell has no track"):
        cell_scene(bare, track=1.0)
    with pytest.raises(InputError, match="the cell has no turntable"):
        cell_scene(bare, table=0.5)
    # a cell without track or turntable: the robot and the world axes
    names = [i.name for i in cell_scene(bare).items]
    assert names[:2] == ["world", "robot R"] and not any("track" in n or "turn" in n for n in names)


@pytest.mark.parametrize("name", ["kuka_kr16", "abb_irb460", "puma560"])
def test_links_follow_the_dh_parameters(name):
    # Each link is drawn as its two DH segments: d along Z_{i-1} and a along X_i (standard), or
    # a along X_{i-1} and d along Z_i (modified, Craig; the IRB 460 with its passive joints).
    robot = load_robot(name)
    q = np.random.default_rng(4).uniform(np.maximum(robot.lower, -2), np.minimum(robot.upper, 2))
    cp = chain_pose(robot, q)
    F, v = cp.frames, cp.vertices
    for i, j in enumerate(robot.joints):
        first, second = v[2 * i + 1] - v[2 * i], v[2 * i + 2] - v[2 * i + 1]
        if robot.convention == "standard":
            d, a = F[i, :3, :3].T @ first, F[i + 1, :3, :3].T @ second
            np.testing.assert_allclose(d[:2], 0, atol=1e-12)
            np.testing.assert_allclose(a[1:], 0, atol=1e-12)
            if not j.prismatic:
                assert d[2] == pytest.approx(j.d, abs=1e-12) and a[0] == pytest.approx(j.a, abs=1e-12)
        else:
            a, d = F[i, :3, :3].T @ first, F[i + 1, :3, :3].T @ second
            np.testing.assert_allclose(a[1:], 0, atol=1e-12)
            np.testing.assert_allclose(d[:2], 0, atol=1e-12)
            assert a[0] == pytest.approx(j.a, abs=1e-12)
    # the joint axes point the way positive values turn: a small step of axis k about its arrow
    for k in range(len(robot.joints)):
        if robot.joints[k].passive:
            continue
        dq = np.zeros(robot.n_joints)
        dq[list(robot.axes).index(robot.joints[k])] = 1e-6
        T0, T1 = robot.fk(q), robot.fk(q + dq)
        w = T1[:3, :3] @ T0[:3, :3].T
        omega = np.array([w[2, 1], w[0, 2], w[1, 0]]) / 1e-6
        if robot.coupling is None:
            np.testing.assert_allclose(omega, cp.axis_directions[k], atol=1e-5)


def test_browser_renders_the_view_without_error(tmp_path, capsys):
    exe = _chromium()
    out = tmp_path / "cell.html"
    code, _, err = run(capsys, "view", EXAMPLE, "--joints", JOINTS, "--track", TRACK, "--table",
                       TABLE, "-o", out)
    assert code == 0, err
    assert re.fullmatch(r".*cell\.html: 3D view of kr16_track_turntable, 4\.\d MB; open it in a "
                        r"browser\n", err)
    dom, console, shot = render(exe, out, tmp_path)
    # plotly drew the scene (the page's own script marks the body), with no JavaScript error
    assert 'data-scene="rendered"' in dom
    assert not js_errors(console), console
    import matplotlib.image

    img = matplotlib.image.imread(shot)[..., :3]
    # Not blank: the triads' pure red, green and blue axes, the grey links, the violet joint axes.
    for rgb, least in (((1, 0, 0), 100), ((0, 0.5, 0), 100), ((0, 0, 1), 100),
                       ((0.41, 0.41, 0.41), 1000), ((0.58, 0, 0.83), 50)):
        count = np.all(np.abs(img - np.array(rgb)) < 0.12, axis=-1).sum()
        assert count > least, (rgb, count)


def test_view_command_refuses_bad_input_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "cell.html"
    missing = tmp_path / "missing_robot.yaml"
    missing.write_text(EXAMPLE.read_text().replace("model: kuka_kr16", "model: kr16_arm.yaml"))
    cases = [
        ([missing], r"key 'robot.model' names model file '.*kr16_arm.yaml', which does not exist"),
        ([EXAMPLE, "--joints", "0,60,90,0,0,0"],
         r"--joints: A2 = 60 deg is outside its limits \[-155, 35\] deg"),
        ([EXAMPLE, "--joints", "0,-90,90,0,0"], "--joints needs 6 comma-separated values, got 5"),
        ([EXAMPLE, "--track", "7000"],
         r"track position 7000 mm is outside the track limits \[0, 6000\] mm"),
        ([EXAMPLE, "--table", "30,90"], "a turntable has one angle"),
        ([POSITIONER, "--table", "30"], "positioner 'DKP_2' has 2 axes"),
        ([EXAMPLE, "--tool", "torch"], "--tool says which tool the --reach map was made with"),
        ([tmp_path / "none.yaml"], "none.yaml"),
    ]
    for args, message in cases:
        code, _, err = run(capsys, "view", *args, "-o", out)
        assert code == 2, (args, err)
        assert re.search(message, err), (args, err)
        assert "Traceback" not in err and not out.exists()
    # -o onto an input: refused before it is read, the input intact
    # (a name whose ending says no kind of file, so that only the input check can refuse it)
    copy = tmp_path / "cell.dat"
    copy.write_text(EXAMPLE.read_text())
    for args in ([copy, "-o", copy], [EXAMPLE, "--reach", copy, "-o", copy]):
        code, _, err = run(capsys, "view", *args)
        assert code == 2 and "names the same file as" in err and "write to another file" in err
        assert copy.read_text() == EXAMPLE.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.dat", "missing_robot.yaml"]


def test_page_of_a_scene_has_its_title(tmp_path):
    scene = cell_scene(Cell.load(POSITIONER), table=np.radians([10, 20]))
    text = page(scene)
    assert f"<title>{scene.title}</title>" in text and RENDERED in text


def test_public_names_are_imported_on_first_use():
    from robotcell import view

    assert set(view.__all__) == set(view._LAZY) and set(view.__all__) <= set(dir(view))
    for name in view.__all__:
        assert getattr(view, name).__module__ == view._LAZY[name]
    with pytest.raises(AttributeError, match="has no attribute 'nothing'"):
        view.nothing  # noqa: B018
