"""Long touch files: every calibration costs time and memory linear in the number of touches.

A 3-point frame, a workpiece or an ABC 2-point tool used to estimate each touch's free
coordinate (its place along the X axis, in the plane) as a parameter of its own, so the fit had
as many parameters as touches: an N x N normal matrix, finite differences over N parameters,
3,000 touches in more than two minutes. The free coordinates are now eliminated (each touch
measures the directions across its line or plane), the leave-one-out tests come from one thin QR
factorisation, and no step forms an N x N matrix (the circle fit that starts a positioner took
a full SVD of its points). Times are measured by ``benchmarks/bench_calibrate.py``; these tests
count what does not depend on the machine:

* the parameters of the fit and the evaluations of the model do not grow with the touches
  (between 300 and 3,000 touches, at most 1.5 times the evaluations);
* the peak memory per touch does not grow from 500 to 5,000 touches (at most 1.5 times; a
  matrix of N x N, or of a quarter of the touches squared as the circle fit's SVD, makes it
  grow nearly tenfold or nearly twofold), and stays below 12 kB per touch at 5,000 touches,
  where an N x N matrix of doubles alone takes 40 kB per touch.
"""

import tracemalloc

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robotcell.calibration import fitting
from robotcell.calibration.frame import external_tcp, frame_3point, frame_npoint
from robotcell.calibration.tcp import calibrate_tool
from robotcell.calibration.track import calibrate_track
from robotcell.calibration.turntable import calibrate_turntable
from robotcell.calibration.workpiece import calibrate_workpiece
from robotcell.cell import Cell
from robotcell.identification.positioner import calibrate_positioner
from robotcell.kinematics.transforms import make_pose, rot_z, transform_points

NOISE = 1e-4
T_FRAME = make_pose(Rotation.from_rotvec([0.1, -0.2, 0.6]).as_matrix(), [1.2, -0.3, 0.5])
T_R_B = make_pose(Rotation.from_rotvec([0.02, -0.01, 0.7]).as_matrix(), [1.2, 0.3, 0.4])
TCP = np.array([0.01, -0.02, 0.2])
PIVOT = np.array([1.1, 0.2, 0.5])
R_TOOL = Rotation.from_euler("zyx", [10, -80, 5], degrees=True).as_matrix()
CHAIN = Cell.load("examples/cell_kr16_positioner.yaml").turntable.chain


def roles_and_local(rng, n):
    third = n // 3
    roles = ["origin"] * third + ["x"] * third + ["xy"] * (n - 2 * third)
    local = np.concatenate([np.zeros((third, 3)),
                            np.c_[rng.uniform(0.1, 0.4, third), np.zeros((third, 2))],
                            np.c_[rng.uniform(0.0, 0.3, n - 2 * third),
                                  rng.uniform(0.1, 0.3, n - 2 * third), np.zeros(n - 2 * third)]])
    return roles, local


def flange(rng, points):
    """Flange poses placing each tool point (flange frame) on PIVOT, tilted about 35 deg."""
    n = len(points)
    tilt = rng.normal(0.0, 0.6, (n, 3)) * [1, 1, 0.3]
    R = (Rotation.from_rotvec(tilt) * Rotation.from_euler("y", 90, degrees=True)).as_matrix()
    return make_pose(R, PIVOT + rng.normal(0.0, NOISE, (n, 3)) - np.einsum("nij,nj->ni", R,
                                                                            points))


def noisy(rng, p):
    return p + rng.normal(0.0, NOISE, p.shape)


def tcp(rng, n):
    return lambda: calibrate_tool(flange(rng, np.tile(TCP, (n, 1))), prior_sigma=NOISE)


def tcp_abc(rng, n):
    q = n // 4
    touches = flange(rng, np.tile(TCP, (n - 2 * q, 1)))
    axis = flange(rng, TCP - np.outer(rng.uniform(0.06, 0.12, q), R_TOOL[:, 0]))
    plane = flange(rng, TCP + np.c_[rng.uniform(0.0, 0.05, q), rng.uniform(0.05, 0.1, q)]
                   @ R_TOOL[:, :2].T)
    return lambda: calibrate_tool(touches, axis, plane, prior_sigma=NOISE)


def frame(rng, n):
    roles, local = roles_and_local(rng, n)
    p = noisy(rng, transform_points(T_FRAME, local))
    return lambda: frame_3point(p, roles, NOISE)


def npoint(rng, n):
    q = rng.uniform(-0.3, 0.3, (n, 3))
    p = noisy(rng, transform_points(T_FRAME, q))
    return lambda: frame_npoint(p, q, NOISE)


def external(rng, n):
    roles, local = roles_and_local(rng, n)
    p = noisy(rng, transform_points(T_FRAME, local))
    return lambda: external_tcp(p, ["tcp" if r == "origin" else r for r in roles], NOISE)


def track(rng, n):
    e = rng.uniform(0.0, 2.0, n)
    p = noisy(rng, np.array([1.5, 0.8, 0.3]) - np.outer(e, [1, 0, 0]))
    return lambda: calibrate_track(e, p, prior_sigma=NOISE)


def turntable(rng, n):
    theta = rng.uniform(0.0, 2 * np.pi, n)
    p = noisy(rng, transform_points(T_R_B, np.einsum("nij,j->ni", rot_z(theta), [0.3, 0, 0])))
    return lambda: calibrate_turntable(theta, p, prior_sigma=NOISE)


def workpiece(rng, n):
    roles, local = roles_and_local(rng, n)
    theta = rng.uniform(0.0, 2 * np.pi, n)
    on_table = transform_points(make_pose(np.eye(3), [0.05, 0.0, 0.1]), local)
    p = noisy(rng, transform_points(T_R_B, np.einsum("nij,nj->ni", rot_z(theta), on_table)))
    return lambda: calibrate_workpiece(theta, p, roles, T_R_B, prior_sigma=NOISE)


def positioner(nominal):
    def make(rng, n):
        grid = np.radians(np.c_[rng.choice([-30.0, 0.0, 30.0], n),
                                rng.choice([0.0, 90.0, 180.0, 270.0], n)])
        p = noisy(rng, (CHAIN.fk(grid, np.eye(4)) @ [0.2, 0.0, 0.0, 1.0])[:, :3])
        return lambda: calibrate_positioner(grid, p, nominal=nominal, prior_sigma=NOISE)
    return make


PROCEDURES = {"tcp": tcp, "tcp-abc-2point": tcp_abc, "frame-3point": frame,
              "frame-npoint": npoint, "external-tcp": external, "track": track,
              "turntable": turntable, "workpiece": workpiece,
              "positioner": positioner(CHAIN), "positioner-from-circles": positioner(None)}
#: Procedures on the identification engine, whose fit is not :func:`fitting.fit`.
ENGINE = {"positioner", "positioner-from-circles"}


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


@pytest.mark.parametrize("name", [n for n in PROCEDURES if n not in ENGINE])
def test_fit_size_and_evaluations_do_not_grow_with_the_touches(name, monkeypatch):
    rng = np.random.default_rng(1)
    small = counted(monkeypatch, PROCEDURES[name](rng, 300))
    large = counted(monkeypatch, PROCEDURES[name](rng, 3000))
    assert max(small[0]) == max(large[0]) <= 9, (small, large)
    assert large[1] <= 1.5 * small[1] + 10, (small, large)


def peak_per_touch(make, n: int) -> float:
    """Peak memory (bytes) allocated while calibrating ``n`` touches, per touch."""
    run = make(np.random.default_rng(2), n)
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        run()
        return tracemalloc.get_traced_memory()[1] / n
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("name", list(PROCEDURES))
def test_no_matrix_grows_with_the_square_of_the_touches(name):
    small, large = (peak_per_touch(PROCEDURES[name], n) for n in (500, 5000))
    assert large < 1.5 * small and large < 12_000, (name, small, large)
