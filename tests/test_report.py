"""HTML reports: verdicts, files, and the page as a real headless browser renders it."""

import base64
import json
import os
import re
import shutil
import subprocess
from pathlib import Path

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
    """The PNG images embedded in a report page, decoded."""
    return [base64.b64decode(b) for b in re.findall(r'src="data:image/png;base64,([^"]+)"', page)]


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
    # Every <img> is an embedded PNG: the page refers to no other file.
    assert page.count("<img ") == 2
    pngs = embedded_pngs(page)
    assert len(pngs) == 2
    for png in pngs:
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 5000


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
    sig = re.search(r"<tr><th>axis</th><td>(.*?)</td>", page.split("1-sigma uncertainty")[1]).group(1)
    assert "0.0000" not in sig


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
    exe = _chromium()
    written = write_report(frame_result(), tmp_path / "made" / "report.html")[0]
    # The page alone, copied into an empty folder, as a user mails or copies it.
    alone = tmp_path / "copy"
    alone.mkdir()
    page = Path(shutil.copy(written, alone))
    assert [p.name for p in alone.iterdir()] == ["report.html"]
    url = page.resolve().as_uri()
    dom = _run_chromium(exe, tmp_path, "--virtual-time-budget=5000", "--dump-dom", url).stdout
    # The page's own script marks the body once every <img> has loaded with a size
    # (complete and naturalWidth > 0).
    assert 'data-figures="loaded"' in dom
    shot = tmp_path / "shot.png"
    _run_chromium(exe, tmp_path, "--window-size=1000,2600", f"--screenshot={shot}", url)
    import matplotlib.image

    img = matplotlib.image.imread(shot)[..., :3]
    # Bars of the residual figure are matplotlib's tab:blue (31, 119, 180); the verdict banner
    # is green. Both must be visible in the rendered page.
    blue = np.all(np.abs(img - np.array([31, 119, 180]) / 255) < 0.06, axis=-1).sum()
    green = np.all(np.abs(img - np.array([0xD8, 0xF3, 0xDC]) / 255) < 0.02, axis=-1).sum()
    assert blue > 500 and green > 5000
    # The 3D view: its residual vectors are tab:orange (255, 127, 14), in no other figure.
    orange = np.all(np.abs(img - np.array([255, 127, 14]) / 255) < 0.06, axis=-1).sum()
    assert orange > 50
