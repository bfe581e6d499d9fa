"""``robotcell identify --report``: the identification's HTML page, and how a browser renders it."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import configurations, measure, perturbed, truth_chain, write_csv
from test_report import _chromium, _run_chromium, embedded_pngs

from robotcell import load_robot

NOISE = 0.02e-3


@pytest.fixture(scope="module")
def report_page(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("identify_report")
    rng = np.random.default_rng(31)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    write_csv(tmp / "tracker.csv", measure(ch, x, configurations(nominal, 40, rng), rng, NOISE))
    return tmp


def test_report_holds_every_section(report_page, capsys):
    page_path = report_page / "made" / "report.html"
    code, stdout, stderr = run(capsys, "identify", report_page / "tracker.csv", "--robot", "kuka_kr16",
                               "--accuracy", "0.02", "--report", page_path)
    assert code == 0, stderr
    assert f"report written to {page_path}" in stdout
    assert [p.name for p in page_path.parent.iterdir()] == ["report.html"]
    page = page_path.read_text()
    assert re.search(r'class="verdict (good|check)"><b>(GOOD|CHECK)</b>: \w', page)
    # Errors before and after, the cross-validation (5 folds by default), fixed parameters with
    # their reason, parameters with sigma, correlations, observability against random sets.
    for text in ("Position error before and after identification", "without its fold (5 folds)",
                 "A1.theta</b>: absorbed by the pose of the robot base", "A2.a", "1-sigma",
                 "Largest correlations", "random sets of as many configurations", "row 40"):
        assert text in page, text
    rms = re.search(r"<td>identified</td><td>[\d.]+</td><td>([\d.]+)</td>", page)
    assert 0.01 < float(rms.group(1)) < 0.05  # mm, the noise floor
    pngs = embedded_pngs(page)
    assert page.count("<img ") == len(pngs) == 3  # fit, cross-validation, observability
    assert all(p[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)


def test_report_renders_in_headless_chromium(report_page, tmp_path, capsys):
    exe = _chromium()
    made = tmp_path / "made.html"
    code, _, stderr = run(capsys, "identify", report_page / "tracker.csv", "--robot", "kuka_kr16",
                          "--accuracy", "0.02", "--folds", "4", "--report", made)
    assert code == 0, stderr
    alone = tmp_path / "copy"
    alone.mkdir()
    page = Path(shutil.copy(made, alone / "report.html"))
    url = page.resolve().as_uri()
    dom = _run_chromium(exe, tmp_path, "--virtual-time-budget=5000", "--dump-dom", url).stdout
    assert 'data-figures="loaded"' in dom and "(4 folds)" in dom
    shot = tmp_path / "shot.png"
    _run_chromium(exe, tmp_path, "--window-size=1000,3000", f"--screenshot={shot}", url)
    import matplotlib.image

    img = matplotlib.image.imread(shot)[..., :3]
    # The identified model's errors are drawn in tab:blue; the verdict banner in its colour.
    blue = np.all(np.abs(img - np.array([31, 119, 180]) / 255) < 0.06, axis=-1).sum()
    banner = [0xD8, 0xF3, 0xDC] if 'verdict good' in made.read_text() else [0xFF, 0xF3, 0xBF]
    colour = np.all(np.abs(img - np.array(banner) / 255) < 0.02, axis=-1).sum()
    assert blue > 300 and colour > 5000


def test_report_of_pose_measurements_and_a_coupling(tmp_path, capsys):
    # The real UR10 set (6D probe): orientation errors in the page; a stated J2/J3 factor on a
    # synthetic arm: the check with and without it.
    data = Path(__file__).resolve().parents[1] / "examples" / "identification"
    page = tmp_path / "ur10.html"
    code, _, stderr = run(capsys, "identify", data / "ipa_ur10_random_poses.csv", "--robot",
                          data / "ur10_cb3.yaml", "--accuracy", "0.5", "--folds", "3", "--report", page)
    assert code == 0, stderr
    assert "orientation mean (deg)" in page.read_text()
    rng = np.random.default_rng(23)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng, coupling=-1.0)
    write_csv(tmp_path / "f.csv", measure(ch, x, configurations(nominal, 40, rng), rng, NOISE))
    code, _, stderr = run(capsys, "identify", tmp_path / "f.csv", "--robot", "kuka_kr16", "--j23-factor",
                          "-1", "--accuracy", "0.02", "--folds", "3", "--report", tmp_path / "f.html")
    assert code == 0, stderr
    assert "J2/J3 coupling</h2><p>k = -1:" in (tmp_path / "f.html").read_text()
