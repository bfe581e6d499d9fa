"""``robotcell identify --report``: the identification's HTML page, and how a browser renders it."""

import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from identification_helpers import configurations, measure, perturbed, truth_chain, write_csv
from test_report import _chromium, embedded_pngs
from view_helpers import js_errors, render

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
    # the 3D scene of the measurements, plotly.js inline; the page under 5 MB
    assert "<h2>3D view of the measurements</h2>" in page and "Plotly.newPlot(" in page
    assert "<script src=" not in page and len(page.encode()) < 5_000_000


def test_report_renders_in_headless_chromium(report_page, tmp_path, capsys):
    exe = _chromium()
    made = tmp_path / "made.html"
    code, _, stderr = run(capsys, "identify", report_page / "tracker.csv", "--robot", "kuka_kr16",
                          "--accuracy", "0.02", "--folds", "4", "--report", made)
    assert code == 0, stderr
    # the page alone in an empty folder: its figures loaded, its 3D scene drawn, no error
    dom, console, shot = render(exe, made, tmp_path, size=(1000, 3000))
    assert 'data-figures="loaded"' in dom and "(4 folds)" in dom
    assert 'data-scene="rendered"' in dom and not js_errors(console), console
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
    assert "J2/J3 coupling</h2><p>the data support k = -1:" in (tmp_path / "f.html").read_text()


def test_the_scene_shows_the_targets_the_residuals_and_both_arms():
    from view_helpers import figure_from_page, traces, xyz

    from robotcell.identification import identify
    from robotcell.view.arm import chain_pose
    from robotcell.view.identification import identification_scene
    from robotcell.view.plot import page

    rng = np.random.default_rng(31)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    meas = measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)
    result = identify(nominal, meas, sigma=NOISE)
    scene = identification_scene(result, meas.q, meas.points)
    fig = figure_from_page(page(scene))
    # every measured target, to 1 um, the outlier rows apart
    drawn = np.vstack([xyz(t) for t in traces(fig, "measured targets")
                       + traces(fig, "measured targets (outliers)")])
    flat = meas.points.reshape(-1, 3) * 1e3
    assert len(drawn) == len(flat) == 80
    assert np.abs(drawn[:, None] - flat[None]).max(axis=-1).min(axis=1).max() < 5e-4
    # the residuals of the identified model, magnified by the factor the scene states
    factor = float(re.search(r"residual vectors of the identified model magnified (\d+) x",
                             " ".join(scene.notes))[1])
    shafts = xyz(traces(fig, f"residuals x {factor:g}", "shafts")[0])
    r = result.residuals.reshape(-1, 3) * 1e3
    np.testing.assert_allclose(shafts[1::3] - shafts[0::3], factor * r, rtol=0, atol=1e-3)
    # the nominal arm at row 1 on the identified base; the identified one on its own axes, its
    # difference from the nominal magnified by the second stated factor
    nom = chain_pose(nominal, meas.q[0], result.base)
    ident = chain_pose(result.robot, meas.q[0], result.base)
    np.testing.assert_allclose(xyz(traces(fig, "nominal arm (row 1)")[0]), nom.vertices * 1e3,
                               rtol=0, atol=5e-4)
    gain = float(re.search(r"difference from the nominal magnified (\d+) x",
                           " ".join(scene.notes))[1])
    arm = xyz(traces(fig, f"identified arm, its difference x {gain:g}")[0])
    on = nom.vertices * 1e3 + (arm - nom.vertices * 1e3) / gain
    np.testing.assert_allclose(on[-1], ident.flange[:3, 3] * 1e3, rtol=0, atol=0.05)
    o, z = ident.frames[:, :3, 3] * 1e3, ident.frames[:, :3, 2]
    origins = on[0:-1:2]  # the DH origins, each on its own identified axis
    off = (origins - o) - np.sum((origins - o) * z, axis=1, keepdims=True) * z
    assert np.abs(off).max() < 0.05
    assert np.linalg.norm(on - nom.vertices * 1e3, axis=1).max() < 20  # mm: not metres away
