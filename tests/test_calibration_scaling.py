"""Long touch files: every calibration costs time and memory linear in the number of touches.

A 3-point frame, a workpiece or an ABC 2-point tool used to estimate each touch's free
coordinate (its place along the X axis, in the plane) as a parameter of its own, so the fit had
as many parameters as touches: an N x N normal matrix, finite differences over N parameters,
3,000 touches in more than two minutes. The free coordinates are now eliminated (each touch
measures the directions across its line or plane), the leave-one-out tests come from one thin QR
factorisation, and no step forms an N x N matrix (the circle fit that starts a positioner took
a full SVD of its points). Times are measured by ``benchmarks/bench_calibrate.py`` on the same
designs (``long_touches.py``; the external TCP is the 3-point frame's fit); these tests count
what does not depend on the machine:

* the parameters of the fit and the evaluations of the model do not grow with the touches
  (between 300 and 3,000 touches, at most 1.5 times the evaluations);
* the peak memory per touch does not grow from 500 to 5,000 touches (at most 1.3 times; it is
  constant within 3 %, where a matrix of N x N makes it grow nearly tenfold, and one of a
  third of the touches squared, as the circle fit's SVD, 1.5 times), and stays below 12 kB
  per touch at 5,000 touches, where an N x N matrix of doubles alone takes 40 kB per touch.
"""

import tracemalloc

import numpy as np
import pytest
from long_touches import DESIGNS, NOISE

from robotcell.calibration import fitting

#: Procedures on the identification engine, whose fit is not :func:`fitting.fit`.
ENGINE = {"positioner", "positioner-from-circles"}


def calibration(name: str, rng, n: int):
    """The calibration of ``n`` touches of procedure ``name``, ready to run."""
    calibrate, cell, table, keywords = DESIGNS[name](rng, n)
    return lambda: calibrate(cell, table, sigma=NOISE, **keywords).result


def counted(monkeypatch, run):
    """Parameters and model evaluations of every least-squares fit that ``run`` makes."""
    fits = []
    real = fitting.least_squares

    def spy(fun, x0, *args, **kwargs):
        calls = [0]

        def counting(x):
            calls[0] += 1
            return fun(x)

        fits.append((np.size(x0), calls))
        return real(counting, x0, *args, **kwargs)

    monkeypatch.setattr(fitting, "least_squares", spy)
    run()
    monkeypatch.setattr(fitting, "least_squares", real)
    return [p for p, _ in fits], sum(c[0] for _, c in fits)


@pytest.mark.parametrize("name", [n for n in DESIGNS if n not in ENGINE])
def test_fit_size_and_evaluations_do_not_grow_with_the_touches(name, monkeypatch):
    rng = np.random.default_rng(1)
    small = counted(monkeypatch, calibration(name, rng, 300))
    large = counted(monkeypatch, calibration(name, rng, 3000))
    assert max(small[0]) == max(large[0]) <= 9, (small, large)
    assert large[1] <= 1.5 * small[1] + 10, (small, large)


def peak_per_touch(name: str, n: int) -> float:
    """Peak memory (bytes) allocated while calibrating ``n`` touches, per touch (after a first
    calibration, whose imports are not counted)."""
    calibration(name, np.random.default_rng(3), 50)()
    run = calibration(name, np.random.default_rng(2), n)
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        run()
        return tracemalloc.get_traced_memory()[1] / n
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("name", list(DESIGNS))
def test_no_matrix_grows_with_the_square_of_the_touches(name):
    small, large = (peak_per_touch(name, n) for n in (500, 5000))
    assert large < 1.3 * small and large < 12_000, (name, small, large)
