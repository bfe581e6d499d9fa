"""The options of an identification, as one object or keyword by keyword, give one result."""

import numpy as np
import pytest
from identification_helpers import configurations, measure, perturbed, truth_chain

from robotcell import load_robot
from robotcell.errors import InputError
from robotcell.identification import IdentifyOptions, cross_validate, identify

NOISE = 0.02e-3


@pytest.fixture(scope="module")
def kr16_measured():
    rng = np.random.default_rng(5)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    return nominal, measure(ch, x, configurations(nominal, 40, rng), rng, NOISE)


def test_options_object_and_keywords_give_the_same_identification(kr16_measured):
    nominal, meas = kr16_measured
    by_keyword = identify(nominal, meas, sigma=NOISE, scale=True)
    by_object = identify(nominal, meas, options=IdentifyOptions(sigma=NOISE, scale=True))
    assert by_object.free == by_keyword.free
    np.testing.assert_array_equal(by_object.residuals, by_keyword.residuals)
    assert by_object.touch_sigma == NOISE and by_object.scale.any()


def test_a_keyword_replaces_the_field_of_the_options(kr16_measured):
    nominal, meas = kr16_measured
    res = identify(nominal, meas, options=IdentifyOptions(sigma=1e-3, scale=True), sigma=NOISE)
    assert res.touch_sigma == NOISE and res.scale.any()
    cv = cross_validate(nominal, meas, folds=2, options=IdentifyOptions(sigma=NOISE))
    assert cv.stats()["after_rms_mm"] < 0.1


def test_a_former_or_unknown_keyword_is_refused_by_name(kr16_measured):
    nominal, meas = kr16_measured
    with pytest.raises(TypeError, match="unexpected keyword argument 'point_sigma'"):
        identify(nominal, meas, point_sigma=NOISE)


def test_a_bad_accuracy_in_the_options_names_sigma(kr16_measured):
    nominal, meas = kr16_measured
    with pytest.raises(InputError, match="sigma must be a positive number"):
        identify(nominal, meas, options=IdentifyOptions(sigma=0.0))
