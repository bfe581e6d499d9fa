"""Reading 3D views back, and rendering them in a real headless browser, for the view tests.

A view's figure (or the page that holds it) is read back by the ``meta`` of its traces
(robotcell.view.plot): triads as origins and axis tips, lines as vertices, in mm.

Run as a script, it writes the picture of the view that the README shows:

    python tests/view_helpers.py docs/view.png

(the view of examples/cell_kr16_track_turntable.yaml rendered by Debian's Chromium, as the
browser test renders it, cropped to the page, in 64 colours).
"""

import json
import re
import shutil
import sys
from pathlib import Path

import numpy as np
from test_report import _chromium, _run_chromium

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "cell_kr16_track_turntable.yaml"
#: The configuration the browser test and the README picture show (deg, mm, deg): the torch
#: 50 mm above the part's origin, pointing down, at table angle 150 deg (the README's cell.ik).
JOINTS, TRACK, TABLE = "-70,-48,67,-8,26,-169", 2324.0, 150.0
#: WebGL in headless Chromium, without a GPU: the SwiftShader software renderer.
WEBGL = ("--use-angle=swiftshader", "--enable-unsafe-swiftshader")


def figure_from_page(text):
    """The figure a page of robotcell.view.plot holds: ``{"data", "layout", "frames"}``."""
    decoder = json.JSONDecoder()
    start = text.index("Plotly.newPlot(")
    at = text.index(",", start) + 1  # after the id of the div
    values = []
    for _ in range(2):  # data, layout
        while text[at] in " \n,":
            at += 1
        value, at = decoder.raw_decode(text, at)
        values.append(value)
    frames = []
    if "Plotly.addFrames(" in text:
        at = text.index(",", text.index("Plotly.addFrames(")) + 1
        while text[at] in " \n":
            at += 1
        frames = decoder.raw_decode(text, at)[0]
    return {"data": values[0], "layout": values[1], "frames": frames}


def traces(fig, item, part=None):
    """The traces of scene item ``item`` (and of its ``part``), in the order drawn."""
    return [t for t in fig["data"] if t.get("meta", {}).get("item") == item
            and (part is None or t["meta"]["part"] == part)]


def xyz(trace):
    """The points of a trace, shape (N, 3), mm; None (a break) as NaN."""
    return np.array([[np.nan if v is None else v for v in trace[c]] for c in "xyz"]).T


def moving_parts(fig, k, item="cell at the point"):
    """The pieces of a path's moving polyline at step ``k`` (robotcell.view.path.MOVING): piece
    name -> its vertices (N, 3), mm, as the page's animation frame ``k`` draws them."""
    index = next(i for i, t in enumerate(fig["data"]) if t.get("meta", {}).get("item") == item)
    base = fig["data"][index]
    frame = fig["frames"][k]
    drawn = xyz({**base, **frame["data"][frame["traces"].index(index)]})
    return {name: drawn[a:b] for name, a, b in base["meta"]["parts"]}


def triads(fig, item):
    """Frames of a Triads item: label -> (origin (3,), axis tips (3, 3) as rows X, Y, Z, length),
    all mm."""
    origins = traces(fig, item, "origins")[0]
    tips = [xyz(traces(fig, item, c)[0])[1::3] for c in "xyz"]
    length = traces(fig, item, "x")[0]["meta"]["length_mm"]
    return {label: (xyz(origins)[k], np.array([t[k] for t in tips]), length)
            for k, label in enumerate(origins["text"])}


def assert_triad(frame, T, tol=1e-6):
    """A triad read back is the pose ``T`` (m) to ``tol`` mm: origin and every axis tip."""
    origin, tips, length = frame
    np.testing.assert_allclose(origin, T[:3, 3] * 1e3, rtol=0, atol=tol)
    np.testing.assert_allclose(tips, (T[:3, 3] * 1e3 + length * T[:3, :3].T), rtol=0, atol=tol)


def render(exe, page, tmp_path, size=(1200, 900), screenshot=True):
    """Load ``page`` alone in an empty folder in headless Chromium (WebGL on SwiftShader).

    Returns
    -------
    dom : str
        The DOM after the page's scripts ran.
    console : list of str
        The page's console messages (uncaught errors among them).
    shot : Path or None
        A screenshot (when ``screenshot``), cropped to the page (headless Chromium's viewport is
        shorter than its window; the rest of the image is blank).
    """
    alone = tmp_path / "alone"
    alone.mkdir(exist_ok=True)
    url = Path(shutil.copy(page, alone)).resolve().as_uri()
    shot = tmp_path / "shot.png" if screenshot else None
    extra = ([f"--window-size={size[0]},{size[1]}", "--hide-scrollbars", f"--screenshot={shot}"]
             if screenshot else [])
    run = _run_chromium(exe, tmp_path, *WEBGL, "--enable-logging=stderr", "--v=0",
                        "--virtual-time-budget=8000", *extra, "--dump-dom", url)
    console = [line for line in run.stderr.splitlines() if ":CONSOLE" in line]
    if screenshot:
        crop(shot)
    return run.stdout, console, shot


def crop(png):
    """Cut the blank rows below the page off a screenshot (in place)."""
    import matplotlib.image

    img = matplotlib.image.imread(png)
    ink = np.flatnonzero(np.any(img[..., :3] < 0.98, axis=(1, 2)))
    if ink.size:
        matplotlib.image.imsave(png, img[: ink[-1] + 10])


def js_errors(console):
    """Console messages that are errors: uncaught exceptions, console.error, no WebGL."""
    return [m for m in console if re.search(r"uncaught|error|exception|webgl is not", m, re.IGNORECASE)]


def write_picture(png):
    """The README's picture: the example cell's view, rendered headless, as ``png``."""
    import tempfile

    from robotcell.cli import main

    with tempfile.TemporaryDirectory() as tmp:
        page = Path(tmp) / "cell.html"
        try:
            main(["view", str(EXAMPLE), "--joints", JOINTS, "--track", str(TRACK),
                  "--table", str(TABLE), "-o", str(page)])
        except SystemExit as exc:
            if exc.code:
                raise
        _, console, shot = render(_chromium(), page, Path(tmp), size=(1100, 800))
        assert not js_errors(console), console
        from PIL import Image  # matplotlib's own image library

        # 64 colours (octree: it keeps the small areas of pure red, green and blue) are plenty
        # for lines on white, and keep the file small
        Image.open(shot).convert("RGB").quantize(64, method=Image.Quantize.FASTOCTREE).save(
            png, optimize=True)


if __name__ == "__main__":
    write_picture(sys.argv[1] if len(sys.argv) > 1 else ROOT / "docs" / "view.png")
