"""HTML reports: verdicts, files, and the page as a real headless browser renders it."""

import base64
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest

from robotcell import InputError
from robotcell.calibration.frame import frame_npoint
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.cli import main
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points
from robotcell.report import load_result, verdict, write_report


def frame_result(seed=0, outlier=False, size=0.004, touches=(3,)):
    rng = np.random.default_rng(seed)
    T = make_pose(rot_z(0.4), [1.2, -0.3, 0.5])
    nominal = rng.uniform(-0.4, 0.4, (8, 3))
    measured = transform_points(T, nominal) + rng.normal(0, 1e-4, (8, 3))
    if outlier:
        measured[list(touches)] += [size, 0, 0]
    return frame_npoint(measured, nominal).to_json()


def turntable_result(seed=0):
    """A turntable calibrated in the world frame, as `calibrate turntable --cell` writes it."""
    rng = np.random.default_rng(seed)
    T = make_pose(rot_z(1.2), [2.5, 1.0, 0.5])
    theta = np.radians([0.0, 60.0, 130.0, 200.0, 270.0, 320.0])
    f = transform_points(T, np.stack([0.3 * np.cos(theta), 0.3 * np.sin(theta),
                                      np.zeros_like(theta)], axis=-1))
    f = f + rng.normal(0, 1e-4, f.shape)
    return calibrate_turntable(theta, f).renamed("T_R_B", "T_world_B").to_json()


def embedded_pngs(page):
    """The PNG images of a report page's ``<img>`` elements, decoded."""
    return [base64.b64decode(b) for b in re.findall(r'<img src="data:image/png;base64,([^"]+)"',
                                                      page)]


def test_verdicts():
    good = frame_result()
    assert verdict(good)[0] == "good"
    # A touch the others single out is left out, and the result asks for a check; two far
    # beyond the touch accuracy (no one touch to leave out) make it poor.
    grade, reasons = verdict(frame_result(outlier=True))
    assert grade == "check" and any("left out as outlier" in r for r in reasons)
    grade, reasons = verdict(frame_result(outlier=True, size=0.04, touches=(3, 5)))
    assert grade == "poor" and any("far beyond the default touch accuracy" in r for r in reasons)
    assert verdict({**good, "condition": 500.0})[0] == "check"
    assert verdict({**good, "condition": 5000.0})[0] == "poor"
    assert verdict({**good, "dof": 0, "noise_source": "none"})[0] == "check"


def test_write_report_is_one_self_contained_file(tmp_path):
    files = write_report(frame_result(), tmp_path / "r.html")
    assert files == [tmp_path / "r.html"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]
    page = files[0].read_text()
    assert "GOOD" in page and "frame-npoint" in page
    # Every <img> is an embedded PNG, the 3D scene's plotly.js is inline: the page refers to
    # no other file, and stays under 5 MB.
    assert page.count("<img ") == 1
    pngs = embedded_pngs(page)
    assert len(pngs) == 1
    for png in pngs:
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000
    assert "Plotly.newPlot(" in page and "<script src=" not in page
    assert len(page.encode()) < 5_000_000


def test_report_names_the_frame_of_the_figure(tmp_path):
    # Turntable touches mapped to the world: the figure is in the world, not the robot base.
    page = write_report(turntable_result(), tmp_path / "t.html")[0].read_text()
    assert "in the world frame" in page and "robot base" not in page
    # A frame calibrated in the robot base says so.
    page = write_report(frame_result(), tmp_path / "f.html")[0].read_text()
    assert "in the robot base R frame" in page


def test_report_prints_small_numbers_with_their_units(tmp_path):
    result = turntable_result()
    cov = np.array(result["T_world_B_covariance_mm_rad"])
    assert 0 < cov[5, 5] < 1e-6  # rad^2: four decimals would print 0.0000
    page = write_report(result, tmp_path / "t.html")[0].read_text()
    row = re.search(r"<tr><th>T_world_B_covariance_mm_rad(.*?)</tr>", page, re.DOTALL).group(1)
    assert "mm², mm·rad, rad²" in row
    assert f"{cov[5, 5]:.4g}" in row and "0.0000" not in row
    # The 1-sigma of the axis direction (order 1e-4 and below) is shown with its digits too.
    sig = re.search(r"<tr><th>rotation axis Z_B \(unit vector X, Y, Z\)</th><td>.*?</td>"
                    r"<td>(.*?)</td>", page).group(1)
    assert "0.0000," not in sig and "(direction: " in sig


def test_load_result_errors(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_result(tmp_path / "none.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError, match="not valid JSON"):
        load_result(bad)
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"procedure": "x"}))
    with pytest.raises(InputError, match=r"not a calibration result \(missing residuals_mm"):
        load_result(other)


def main_exit(argv):
    """Exit status of the command line with ``argv``."""
    try:
        main(argv)
    except SystemExit as exc:
        return exc.code or 0
    return 0


def test_report_command(tmp_path, capsys):
    src = tmp_path / "frame.json"
    src.write_text(json.dumps(frame_result()))
    with pytest.raises(SystemExit) as exc:
        main(["report", str(src), "-o", str(tmp_path / "out" / "frame.html")])
        raise SystemExit(0)
    assert (exc.value.code or 0) == 0
    assert "GOOD" in capsys.readouterr().out
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["frame.html"]


def _chromium():
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is not installed; .ci/run installs Debian's chromium")
        pytest.skip("needs Debian's chromium (apt-get install chromium)")
    return exe


def _run_chromium(exe, tmp_path, *args):
    base = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            f"--user-data-dir={tmp_path / 'profile'}"]
    return subprocess.run(base + list(args), capture_output=True, text=True, timeout=120, check=False)


def test_report_renders_figures_in_headless_chromium(tmp_path):
    from view_helpers import js_errors, render

    exe = _chromium()
    written = write_report(frame_result(), tmp_path / "made" / "report.html")[0]
    # The page alone, copied into an empty folder, as a user mails or copies it.
    dom, console, shot = render(exe, written, tmp_path, size=(1000, 2600))
    # The page's own scripts mark the body once every <img> has loaded with a size
    # (complete and naturalWidth > 0), and once plotly has drawn the 3D scene; no error.
    assert 'data-figures="loaded"' in dom and 'data-scene="rendered"' in dom
    assert not js_errors(console), console
    import matplotlib.image

    img = matplotlib.image.imread(shot)[..., :3]
    # Bars of the residual figure are matplotlib's tab:blue (31, 119, 180); the verdict banner
    # is green. Both must be visible in the rendered page.
    blue = np.all(np.abs(img - np.array([31, 119, 180]) / 255) < 0.06, axis=-1).sum()
    green = np.all(np.abs(img - np.array([0xD8, 0xF3, 0xDC]) / 255) < 0.02, axis=-1).sum()
    assert blue > 500 and green > 5000
    # The 3D scene: its residual vectors are darkorange (255, 140, 0), in no other figure.
    orange = np.all(np.abs(img - np.array([255, 140, 0]) / 255) < 0.06, axis=-1).sum()
    assert orange > 50


def test_turntable_report_scene_shows_each_touch_and_the_fitted_circle(tmp_path):
    from view_helpers import figure_from_page, traces, xyz

    result = turntable_result()
    result["residuals_xyz_mm"][3] = [2.0, 0.0, 0.0]  # flagged as an outlier:
    result["points_mm"][3] = (np.array(result["points_mm"][3]) + [2.0, 0.0, 0.0]).tolist()
    result["warnings"].append(f"touch {result['labels'][3]} is an outlier at 3 sigma")
    page = write_report(result, tmp_path / "t.html")[0].read_text()
    fig = figure_from_page(page)
    points = np.array(result["points_mm"])
    # each touch where it was touched, to 1 um; the outlier apart
    good = traces(fig, "touches")[0]
    bad = traces(fig, "touches (outliers)")[0]
    np.testing.assert_allclose(xyz(good), np.delete(points, 3, axis=0), rtol=0, atol=5e-4)
    np.testing.assert_allclose(xyz(bad), points[[3]], rtol=0, atol=5e-4)
    assert bad["text"] == [result["labels"][3]] and "outlier" in bad["hovertext"][0]
    # the fitted circle: the touched point about Z_B at the fitted radius, height_mm below B
    T = np.array(result["matrix"])
    circle = xyz(traces(fig, "fitted circle")[0])
    centre = T[:3, 3] - result["height_mm"] * T[:3, 2]
    np.testing.assert_allclose(np.linalg.norm(circle - centre, axis=1), result["radius_mm"],
                               rtol=0, atol=1e-3)
    np.testing.assert_allclose((circle - centre) @ T[:3, 2], 0.0, atol=1e-3)
    # every touch near the circle, the residual vectors magnified by the factor the scene states
    factor = float(re.search(r"residual vectors magnified (\d+) x", page)[1])
    shafts = xyz(traces(fig, f"residuals x {factor:g}", "shafts")[0])
    res = np.array(result["residuals_xyz_mm"])
    np.testing.assert_allclose(shafts[0::3], points - res, rtol=0, atol=1e-3)
    np.testing.assert_allclose(shafts[1::3], points - res + factor * res, rtol=0, atol=1e-3)
    assert fig["layout"]["scene"]["aspectmode"] == "data"  # equal axes
    assert "in the world frame" in page and "turntable B" in {t["name"] for t in fig["data"]}


def _result_table(page):
    """(quantity, value, 1-sigma, unit) of every row of the page's result tables."""
    rows = []
    for table in re.findall(r'<table class="result">(.*?)</table>', page, re.DOTALL):
        for row in re.findall(r"<tr>(.*?)</tr>", table, re.DOTALL)[1:]:
            rows.append(tuple(re.sub(r"<[^>]+>", "", c) for c in
                              re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", row, re.DOTALL)))
    return rows


def test_demo_reports_for_a_technician_in_headless_chromium(tmp_path, capsys):
    """The demo's reports: each quantity named with its unit and 1-sigma, internals in an
    appendix, 3D scenes on equal axes with the residuals magnified by a stated factor."""
    from view_helpers import figure_from_page, js_errors, render, traces

    exe = _chromium()
    assert main_exit(["demo", "-o", str(tmp_path / "demo")]) == 0
    capsys.readouterr()
    expected = {
        "tcp": ("position of TCP in flange F (X, Y, Z)", "mm"),
        "track": ("position of robot base R in track L (X, Y, Z)", "mm"),
        "turntable": ("orientation of turntable B in world (A, B, C; R = Rz(A) Ry(B) Rx(C))",
                      "deg"),
        "workpiece": ("position of workpiece W in turntable B (X, Y, Z)", "mm"),
    }
    for procedure, (quantity, unit) in expected.items():
        path = tmp_path / "demo" / f"report_{procedure}.html"
        page = path.read_text()
        rows = _result_table(page)
        assert (quantity, unit) in {(r[0], r[3]) for r in rows}, procedure
        # Every quantity has a unit column; the calibrated ones a 1-sigma beside the value.
        result_rows = rows[:[r[0] for r in rows].index("touches")]
        assert result_rows and all(len(r) == 4 for r in rows)
        assert all(r[2] for r in result_rows if r[3] in ("mm", "deg")
                   and not r[0].startswith(("origin above", "arc covered"))), procedure
        # Internals only in the appendix, below the result.
        main_part, appendix = page.split("<h2>Appendix: fit internals</h2>")
        for internal in ("dof", "noise_source", "covariance"):
            assert f"<th>{internal}" not in main_part
        assert "<th>dof" in appendix and "<th>noise_source" in appendix
        # The 3D scene: equal axes (plotly scales the data alike), a touch per residual and
        # the residual vectors magnified by the factor it states (plotly fits the view to
        # everything drawn).
        fig = figure_from_page(page)
        assert fig["layout"]["scene"]["aspectmode"] == "data"
        n = sum(len(t["x"]) for t in traces(fig, "touches") + traces(fig, "touches (outliers)"))
        assert n == len(json.loads((tmp_path / "demo" / f"{procedure}.json").read_text())
                        ["residuals_mm"]), procedure
        assert re.search(r"residual vectors magnified \d+ x", page), procedure
        assert len(page.encode()) < 5_000_000, procedure
        # Rendered by a browser: not blank, the figures loaded, the scene drawn, no error.
        dom, console, shot = render(exe, path, tmp_path, size=(1000, 2000))
        assert 'data-figures="loaded"' in dom and 'data-scene="rendered"' in dom, procedure
        assert not js_errors(console), (procedure, console)
        import matplotlib.image

        img = matplotlib.image.imread(shot)[..., :3]
        assert img.std() > 0.05 and (img < 0.5).mean() > 0.005, procedure  # text and figures
