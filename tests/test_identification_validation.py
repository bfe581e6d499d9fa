"""Cross-validation and pose selection for the identification."""

import math

import numpy as np
import pytest
from identification_helpers import configurations, measure, perturbed, truth_chain

from robotcell import load_robot
from robotcell.errors import InputError
from robotcell.identification import identify
from robotcell.identification.validation import cross_validate, select_configurations

NOISE = 0.02e-3


def test_cross_validation_before_and_after():
    rng = np.random.default_rng(41)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 2, False, rng)
    meas = measure(ch, x, configurations(nominal, 50, rng), rng, NOISE)
    cv = cross_validate(nominal, meas, folds=5, sigma=NOISE)
    assert cv.after.shape == (50, 2) and set(cv.fold) == set(range(5))
    s = cv.stats()
    floor = NOISE * math.sqrt(3.0) * 1e3
    assert s["after_rms_mm"] <= 1.5 * floor  # held-out rows, noise included
    assert s["before_rms_mm"] > 30 * s["after_rms_mm"]
    assert s["after_max_mm"] >= s["after_rms_mm"] >= 0.8 * s["after_mean_mm"]
    with pytest.raises(InputError, match="folds must be between 2"):
        cross_validate(nominal, meas, folds=1)


def test_selected_configurations_beat_random_ones():
    rng = np.random.default_rng(42)
    nominal = load_robot("kuka_kr16")
    sel = select_configurations(nominal, 15, n_targets=3, n_candidates=600, seed=1)
    assert sel.q.shape == (15, 6) and np.all(nominal.within_limits(sel.q))
    assert sel.o1 > sel.o1_random.max()
    # And the identified model predicts better from them than from random configurations.
    ch, x = truth_chain(perturbed(nominal, rng), 3, False, rng)
    qv = configurations(nominal, 300, rng)
    truth = ch.predict(x, qv)[0]

    def rms(q):
        res = identify(nominal, measure(ch, x, q, rng, NOISE), sigma=NOISE)
        return math.sqrt(np.mean(np.sum((res.predict(qv)[0] - truth) ** 2, axis=-1)))

    random_rms = [rms(configurations(nominal, 15, rng)) for _ in range(3)]
    assert rms(sel.q) < min(random_rms)
    with pytest.raises(InputError, match="propose at least"):
        select_configurations(nominal, 2, n_candidates=50)
