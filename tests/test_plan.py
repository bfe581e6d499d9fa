"""Planning: predicted uncertainty of candidate designs, checked by Monte Carlo."""

import math

import numpy as np
import pytest

from robotcell import InputError
from robotcell.studies.demo import demo_cells
from robotcell.studies.plan import DESIGNS, LEVER, plan

TRUTH, _ = demo_cells()


def test_monte_carlo_spread_matches_the_prediction():
    """The RMS error over 150 simulated calibrations is the predicted 1-sigma within 20 %."""
    p = plan(TRUTH, "turntable", noise=1e-4, runs=150, seed=5, tool="torch",
             designs=[{"span": math.radians(180), "radius": 0.25}])
    mc = p.monte_carlo
    assert mc.failures == 0 and mc.runs == 150
    assert mc.position_rms == pytest.approx(mc.position_predicted, rel=0.2)
    assert mc.rotation_rms == pytest.approx(mc.rotation_predicted, rel=0.2)


def test_best_design_has_the_smallest_merit_and_larger_geometry_wins():
    p = plan(TRUTH, "track", noise=1e-4, runs=0, tool="torch")
    feasible = [c for c in p.candidates if math.isfinite(c.merit)]
    assert p.best.merit == min(c.merit for c in feasible)
    assert p.best.design == {"travel": 2.0}          # the longest travel per reference point
    merits = [c.merit for c in p.candidates]
    assert merits == sorted(merits, reverse=True)    # more travel, smaller uncertainty
    for c in feasible:
        assert c.merit == pytest.approx(math.hypot(c.position, LEVER * c.rotation))
    assert p.monte_carlo is None
    assert len(p.touches.q) == 8 and p.touches.noise == 0.0


def test_unreachable_designs_are_reported_not_chosen():
    designs = [{"tilt": math.radians(30)}, {"tilt": math.radians(30), "point": (3.0, 0.0, 0.3)}]
    p = plan(TRUTH, "tcp", noise=1e-4, runs=0, tool="torch", designs=designs)
    assert p.best is p.candidates[0]
    assert "cannot be reached" in p.candidates[1].reason
    assert not math.isfinite(p.candidates[1].merit)


def test_predicted_sigma_scales_with_the_noise():
    a = plan(TRUTH, "tcp", noise=1e-4, runs=0, tool="torch", designs=DESIGNS["tcp"][:2])
    b = plan(TRUTH, "tcp", noise=2e-4, runs=0, tool="torch", designs=DESIGNS["tcp"][:2])
    np.testing.assert_allclose([c.merit for c in b.candidates],
                               [2 * c.merit for c in a.candidates], rtol=1e-6)


def test_errors():
    with pytest.raises(InputError, match="unknown procedure 'laser'"):
        plan(TRUTH, "laser")
    with pytest.raises(InputError, match="noise must be a positive number"):
        plan(TRUTH, "tcp", noise=0.0, tool="torch")
    with pytest.raises(InputError, match=r"noise must be a positive number \(m\) of at least 1e-06"):
        plan(TRUTH, "tcp", noise=1e-200, tool="torch")  # its square underflows: a fit divided by 0
    with pytest.raises(InputError, match="runs must be >= 0"):
        plan(TRUTH, "tcp", runs=-1, tool="torch")
    with pytest.raises(InputError, match="no candidate tcp design can be carried out.*reached"):
        plan(TRUTH, "tcp", runs=0, tool="torch", point=(4.0, 0.0, 0.0))
