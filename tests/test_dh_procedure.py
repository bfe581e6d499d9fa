"""The DH procedure: geometry -> DH table -> FK reproduces the geometry, case by case."""

import math

import numpy as np
import pytest

import robotcell as rc
from robotcell.dhprocedure import AxisChain, dh_from_axes
from robotcell.errors import InputError
from robotcell.kinematics.transforms import make_pose

TOL = 1e-9


def pose_error(A, B):
    """Largest position error (m) and rotation error (rad) between two batches of poses."""
    dp = np.linalg.norm(A[..., :3, 3] - B[..., :3, 3], axis=-1).max()
    R = np.swapaxes(A[..., :3, :3], -1, -2) @ B[..., :3, :3]
    c = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1) / 2, -1, 1)
    s = np.linalg.norm(np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                                 R[..., 1, 0] - R[..., 0, 1]], -1), axis=-1) / 2
    return dp, np.arctan2(s, c).max()


def unit(v):
    return v / np.linalg.norm(v)


def perp(rng, z):
    v = rng.normal(size=3)
    return unit(v - v @ z * z)


def random_chain(rng, n):
    """A chain whose consecutive axes are skew, intersecting, parallel or coincident at random."""
    pts, dirs, types, cases = [rng.normal(size=3) * 0.3], [unit(rng.normal(size=3))], [], []
    types.append(rng.choice(["revolute", "prismatic"]))
    for _ in range(1, n):
        p, z = pts[-1], dirs[-1]
        case = rng.choice(["skew", "intersecting", "parallel", "coincident", "coincident-ish",
                           "nearly parallel"])
        if case == "skew":
            q, w = rng.normal(size=3) * 0.3, unit(rng.normal(size=3))
        elif case == "intersecting":
            q, w = p + rng.normal() * 0.3 * z, unit(rng.normal(size=3))
        elif case == "parallel":
            q, w = p + perp(rng, z) * rng.uniform(0.05, 0.5), z * rng.choice([1, -1])
        elif case == "nearly parallel":  # or antiparallel, by 1e-9..1e-6 rad
            tilt = 10 ** rng.uniform(-9, -6)
            q = p + perp(rng, z) * rng.uniform(0.05, 0.5) + rng.normal() * 0.3 * z
            w = unit(z + tilt * perp(rng, z)) * rng.choice([1, -1])
        elif case == "coincident":
            q, w = p + rng.normal() * z, z * rng.choice([1, -1])
        else:  # within 1e-13 of coincident: treated as coincident at tol 1e-9
            q, w = p + rng.normal() * z + 1e-13 * perp(rng, z), unit(z + 1e-13 * perp(rng, z))
        t = rng.choice(["revolute", "prismatic"])
        pts.append(q)
        dirs.append(w)
        types.append(t)
        cases.append(case)
    flange_kind = rng.choice(["free", "on last axis"])
    zf = dirs[-1] if flange_kind == "on last axis" else unit(rng.normal(size=3))
    origin = pts[-1] + rng.normal() * dirs[-1] if flange_kind == "on last axis" else rng.normal(size=3)
    xf = perp(rng, zf)
    flange = make_pose(np.column_stack([xf, np.cross(zf, xf), zf]), origin)
    return AxisChain(np.array(pts), np.array(dirs), tuple(types), flange), cases


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_library_robots_round_trip_through_their_axes(convention):
    rng = np.random.default_rng(1)
    names = rc.list_robots()
    assert names
    for name in names:
        robot = rc.load_robot(name).uncoupled()  # the chain's own joint values (no coupling)
        chain = AxisChain.from_robot(robot)
        q = rng.uniform(-math.pi, math.pi, (200, robot.n_joints))
        # The reference (product of screw motions) is independent of the DH table...
        dp, dr = pose_error(chain.fk(q), robot.fk(q, tool=np.eye(4)))
        assert dp < TOL and dr < TOL, name
        # ...and the derived model reproduces it.
        der = dh_from_axes(chain, convention)
        dp, dr = pose_error(der.robot.fk(q), chain.fk(q))
        assert dp < TOL and dr < TOL, name
        assert der.robot.convention == convention
        assert der.deviation < TOL  # and so does its model file


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_random_chains_all_cases(convention):
    rng = np.random.default_rng(7)
    seen_cases, seen_types = set(), set()
    for _ in range(150):
        n = int(rng.integers(1, 8))
        chain, _ = random_chain(rng, n)
        signs = rng.choice([1.0, -1.0], n)
        der = dh_from_axes(chain, convention, signs=signs)
        q = rng.uniform(-math.pi, math.pi, (20, n))
        dp, dr = pose_error(der.robot.fk(q), chain.fk(q))
        assert dp < TOL and dr < TOL
        assert [j.sign for j in der.robot.joints] == list(signs)
        seen_cases |= {note.case for note in der.notes}
        seen_types |= set(chain.types)
    assert seen_cases == {"base", "skew", "intersecting", "parallel", "coincident"}
    assert seen_types == {"revolute", "prismatic"}


def test_frames_satisfy_the_procedure():
    """Each Z along its joint axis, X perpendicular to and meeting both Z axes (standard), but
    where nearly parallel axes take Hayati's beta."""
    rng = np.random.default_rng(3)
    for _ in range(30):
        chain, _ = random_chain(rng, 6)
        der = dh_from_axes(chain)
        F = der.frames
        for i in range(6):
            z = F[i, :3, 2]
            assert np.linalg.norm(np.cross(z, chain.directions[i])) < 1e-9
            # the joint axis passes through O_i
            r = F[i, :3, 3] - chain.points[i]
            assert np.linalg.norm(r - r @ chain.directions[i] * chain.directions[i]) < 1e-9
            x = F[i + 1, :3, 0]
            if der.robot.joints[i].beta == 0:
                assert abs(x @ z) < 1e-9
            else:  # Hayati's beta only where the common normal would lie beyond the chain
                assert "as nearly parallel axes, they take the parallel rule" in der.notes[i + 1].text
                assert abs(x @ z) < 0.5  # less than 30 degrees
        assert np.allclose(der.robot.base, F[0])


def test_standard_and_modified_share_theta_and_d():
    # (A nearly parallel pair's normal is perpendicular to Z_k in standard DH and to Z_{k+1} in
    # modified DH: there the two tables differ. The first chain without one.)
    rng = np.random.default_rng(4)
    while True:
        chain, _ = random_chain(rng, 6)
        std, mod = dh_from_axes(chain, "standard").robot, dh_from_axes(chain, "modified").robot
        if not any(j.beta for j in std.joints + mod.joints):
            break
    for js, jm in zip(std.joints, mod.joints):
        assert js.theta == pytest.approx(jm.theta, abs=1e-12)
        assert js.d == pytest.approx(jm.d, abs=1e-12)
    # Craig's row i holds a_{i-1}, alpha_{i-1}: the standard a, alpha moved down one row.
    assert [j.a for j in mod.joints[1:]] == pytest.approx([j.a for j in std.joints[:-1]])
    assert [j.alpha for j in mod.joints[1:]] == pytest.approx([j.alpha for j in std.joints[:-1]])
    assert mod.joints[0].a == 0 and mod.joints[0].alpha == 0


def test_parallel_axes_keep_d_zero_and_x_toward_next_axis():
    # Planar 3R arm: parallel Z axes 0.4 m and 0.3 m apart along +X.
    chain = AxisChain(points=[[0, 0, 0.1], [0.4, 0, 0], [0.7, 0, 0.2]], directions=[[0, 0, 1]] * 3,
                      types=("revolute",) * 3, flange=make_pose(p=[0.9, 0, 0.5]))
    der = dh_from_axes(chain)
    a = [j.a for j in der.robot.joints]
    d = [j.d for j in der.robot.joints]
    assert a[:2] == pytest.approx([0.4, 0.3])
    assert d[:2] == pytest.approx([0.0, 0.0])
    assert [n.case for n in der.notes] == ["base", "parallel", "parallel", "parallel"]
    assert "not unique" in der.notes[1].text and "d = 0" in der.notes[1].text
    assert np.allclose(der.frames[1, :3, 0], [1, 0, 0])


def test_intersecting_x_points_toward_end_effector():
    chain = AxisChain(points=[[0, 0, 0], [0, 0, 0.5]], directions=[[0, 0, 1], [0, 1, 0]],
                      types=("revolute", "revolute"), flange=make_pose(p=[-0.3, 0.2, 0.5]))
    der = dh_from_axes(chain)
    assert der.notes[1].case == "intersecting"
    assert np.allclose(der.frames[1, :3, 0], [-1, 0, 0])  # toward the flange at x < 0
    assert "toward the end effector" in der.notes[1].text


def test_flange_on_last_axis_becomes_frame_n():
    robot = rc.Robot("r", (rc.Joint("revolute", d=0.3, alpha=math.pi / 2),
                           rc.Joint("revolute", d=0.1)), flange=make_pose(p=[0, 0, 0.05]))
    der = dh_from_axes(AxisChain.from_robot(robot))
    assert der.notes[-1].case == "coincident"
    assert np.allclose(der.robot.flange, np.eye(4))
    assert der.robot.joints[-1].d == pytest.approx(0.15)


def test_sign_corrections_flip_z_and_the_sign():
    robot = rc.load_robot("kuka_kr6_r700_sixx")  # a library model: its absence is a failure
    chain = AxisChain.from_robot(robot)
    plain = dh_from_axes(chain).robot
    corrected = dh_from_axes(chain, signs=[j.sign for j in robot.joints]).robot
    # A1 turns about -Z of ROBROOT; with Z_0 along +Z the base height d1 comes out positive.
    assert plain.joints[0].d == pytest.approx(-0.4)
    assert corrected.joints[0].d == pytest.approx(0.4)
    assert corrected.joints[0].sign == -1


def test_zero_direction_names_the_joint():
    with pytest.raises(InputError, match="joint elbow: axis direction has zero length"):
        AxisChain(points=np.zeros((2, 3)), directions=[[0, 0, 1], [0, 0, 0]],
                  types=("revolute", "revolute"), names=("base", "elbow"))


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("second", [[0.0, 0.0, 1.0], [0.3, -0.2, 1.0]])  # coincident, parallel
def test_parallel_prismatic_axes_are_two_d_variables(convention, second):
    # A gantry with a redundant vertical axis (Z1, then Z2 the other way along the same
    # direction), then a rotary axis and a slide: legal, DH holds both as d along one Z.
    chain = AxisChain(points=[[0, 0, 0], second, [0.5, 0, 0], [0.5, 0.1, 0]],
                      directions=[[0, 0, 1], [0, 0, -2], [0, 0, 1], [1, 0, 0]],
                      types=("prismatic", "prismatic", "revolute", "prismatic"),
                      names=("Z1", "Z2", "C", "X"),
                      flange=make_pose(None, [0.7, 0.1, -0.2]))
    der = dh_from_axes(chain, convention)
    assert [j.type for j in der.robot.joints] == ["prismatic", "prismatic", "revolute", "prismatic"]
    q = np.random.default_rng(4).uniform(-1, 1, (50, 4))
    dp, dr = pose_error(der.robot.fk(q), chain.fk(q))
    assert dp < TOL and dr < TOL
    # moving Z1 and Z2 by the same amount leaves the flange where it was
    T = der.robot.fk(np.array([[0.2, 0.2, 0.3, 0.1], [0.0, 0.0, 0.3, 0.1]]))
    assert np.allclose(T[0], T[1], atol=TOL)


def test_bad_arguments():
    chain = AxisChain(points=[[0, 0, 0]], directions=[[0, 0, 1]], types=("revolute",))
    with pytest.raises(InputError, match="convention must be"):
        dh_from_axes(chain, "craig")
    with pytest.raises(InputError, match="signs must be 1 values, each"):
        dh_from_axes(chain, signs=[0.5])
    with pytest.raises(InputError, match="joint J1: type must be"):
        AxisChain(points=[[0, 0, 0]], directions=[[0, 0, 1]], types=("planar",))
    with pytest.raises(InputError, match=r"q must have shape \(\.\.\., 1\)"):
        chain.fk([0.0, 1.0])


def test_screw_fk_is_batched_and_moves_as_expected():
    chain = AxisChain(points=[[1, 0, 0], [0, 0, 0]], directions=[[0, 0, 1], [1, 0, 0]],
                      types=("revolute", "prismatic"))
    T = chain.fk(np.array([[[math.pi / 2, 0.2]] * 3]))
    assert T.shape == (1, 3, 4, 4)
    # The slide of 0.2 along +X (in the zero pose) moves the flange origin to (0.2, 0, 0); the
    # quarter turn about the vertical line x = 1 then carries it to (1, -0.8, 0).
    assert np.allclose(T[0, 0, :3, 3], [1, -0.8, 0])
    assert np.allclose(T[0, 0, :3, :3], rc.rot_z(math.pi / 2))


def test_procedure_reproduces_textbook_tables():
    """PUMA 560 (Corke): every row; KR 6 R700 with its sign corrections: rows 1-5 (frame 6 is
    put on the flange approach axis here, the library puts it elsewhere)."""
    cases = {"puma560": 6, "kuka_kr6_r700_sixx": 5}
    assert set(cases) <= set(rc.list_robots())  # library models: their absence is a failure
    for name in cases:
        robot = rc.load_robot(name)
        der = dh_from_axes(AxisChain.from_robot(robot), signs=[j.sign for j in robot.joints])
        for mine, theirs in list(zip(der.robot.joints, robot.joints))[:cases[name]]:
            assert (mine.a, mine.d, mine.alpha, mine.theta, mine.sign) == pytest.approx(
                (theirs.a, theirs.d, theirs.alpha, theirs.theta, theirs.sign), abs=1e-12), name


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("degrees, case", [(40.0, "skew"), (20.0, "skew"), (1.0, "parallel"),
                                           (1e-7, "parallel")])
def test_axes_whose_common_normal_lies_beyond_the_chain_take_the_parallel_rule(convention,
                                                                               degrees, case):
    # Z_0 along Z; the next axis 0.36 m away, turned about X: their common normal lies 0.2 m /
    # sin(angle) along them, 0.6 m at 20 degrees (within twice the chain's extent of 0.5 m),
    # 11 m at 1 degree and 1e5 km at 1e-7 degrees (beyond it).
    phi = math.radians(degrees)
    chain = AxisChain(points=[[0, 0, 0], [0.3, 0.2, 0.1]],
                      directions=[[0, 0, 1], [0, math.sin(phi), math.cos(phi)]],
                      types=("revolute", "prismatic"), flange=make_pose(p=[0.3, 0.4, 0.3]))
    der = dh_from_axes(chain, convention)
    assert der.notes[1].case == case
    link = der.robot.joints[0 if convention == "standard" else 1]
    assert (link.beta != 0) == (case == "parallel")
    if case == "parallel":
        assert f"the axes are {degrees:.3g} deg from parallel" in der.notes[1].text
        # the normal in the plane of the previous one (d = 0), from Z_0 to the next axis
        assert link.d == 0 and link.a == pytest.approx(math.hypot(0.3, 0.2), rel=1e-2)
    assert max(max(abs(j.a), abs(j.d)) for j in der.robot.joints) < 2.0
    q = np.random.default_rng(5).uniform(-1, 1, (50, 2))
    dp, dr = pose_error(der.robot.fk(q), chain.fk(q))
    assert dp < TOL and dr < TOL and der.deviation < TOL


def test_a_chain_too_far_away_for_a_model_file_is_refused_with_the_reason():
    # A chain 10,000 km from the origin of R: neither double precision (1e-16 of 1e7 m) nor its
    # model file, in mm and degrees (a rounding of 1e-14 rad moves it by 1e-7 m), holds it to
    # 1e-9 m.
    far = 1e7
    chain = AxisChain(points=[[far, 0, 0], [far + 0.3, 0, 0.4]],
                      directions=[[0.1, 0.2, 0.9], [0.3, 1, 0]], types=("revolute", "revolute"),
                      flange=make_pose(p=[far + 0.5, 0, 0.4]))
    with pytest.raises(InputError, match=r"the chain: the DH model as written differs .* by up "
                       r"to .* m or rad \(more than 1e-09\): moving joint\(s\) J1.* with constants "
                       r"up to 9.\d+e\+06 m, the arithmetic .* no DH model exact to 1e-9 m"):
        dh_from_axes(chain)
