"""HTML reports: verdicts, files, and the page as a real headless browser renders it."""

import json
import os
import shutil
import subprocess

import numpy as np
import pytest

from robotcell import InputError
from robotcell.calibration.frame import frame_npoint
from robotcell.cli import main
from robotcell.report import load_result, verdict, write_report
from robotcell.transforms import make_pose, rot_z, transform_points


def frame_result(seed=0, outlier=False, size=0.004):
    rng = np.random.default_rng(seed)
    T = make_pose(rot_z(0.4), [1.2, -0.3, 0.5])
    nominal = rng.uniform(-0.4, 0.4, (8, 3))
    measured = transform_points(T, nominal) + rng.normal(0, 1e-4, (8, 3))
    if outlier:
        measured[3] += [size, 0, 0]
    return frame_npoint(measured, nominal).to_json()


def test_verdicts():
    good = frame_result()
    assert verdict(good)[0] == "good"
    # A flagged touch asks for a check; one far beyond the touch accuracy makes the result poor.
    grade, reasons = verdict(frame_result(outlier=True))
    assert grade == "check" and any("outlier" in r for r in reasons)
    grade, reasons = verdict(frame_result(outlier=True, size=0.04))
    assert grade == "poor" and any("far beyond the default touch accuracy" in r for r in reasons)
    assert verdict({**good, "condition": 500.0})[0] == "check"
    assert verdict({**good, "condition": 5000.0})[0] == "poor"
    assert verdict({**good, "dof": 0, "noise_source": "none"})[0] == "check"


def test_write_report_files(tmp_path):
    files = write_report(frame_result(), tmp_path / "r.html")
    assert [f.name for f in files] == ["r.html", "r_view.png", "r_residuals.png"]
    page = files[0].read_text()
    assert "GOOD" in page and 'src="r_view.png"' in page and "frame-npoint" in page
    for f in files[1:]:
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f.stat().st_size > 5000


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
    assert (tmp_path / "out" / "frame_view.png").is_file()


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
    page = write_report(frame_result(), tmp_path / "report.html")[0]
    url = page.resolve().as_uri()
    dom = _run_chromium(exe, tmp_path, "--virtual-time-budget=5000", "--dump-dom", url).stdout
    # The page's own script marks the body once every <img> has loaded with a size.
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
