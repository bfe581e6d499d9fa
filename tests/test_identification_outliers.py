"""The verdict of an identification counts and names its outlier rows alike."""

import numpy as np
from identification_helpers import configurations, measure, perturbed, truth_chain

from robotcell import load_robot
from robotcell.identification import TargetMeasurements, identify

NOISE = 0.02e-3


def _with_bad_rows(rows: list[int]):
    """A simulated KR 16 identification whose ``rows`` are 0.3 mm off in z."""
    rng = np.random.default_rng(4)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    meas = measure(ch, x, configurations(nominal, 100, rng), rng, NOISE)
    pts = meas.points.copy()
    pts[rows, 0, 2] += 0.3e-3
    return identify(nominal, TargetMeasurements(meas.q, pts), sigma=NOISE)


def test_the_verdict_counts_the_outlier_rows_it_does_not_name():
    bad = [3, 11, 17, 25, 33, 41, 52]
    res = _with_bad_rows(bad)
    assert res.outliers == bad
    verdict, why = res.verdict
    labels = [res.labels[i] for i in bad]
    assert verdict == "check"
    # seven rows: five named, the other two counted, so that count and list agree
    assert f"7 outlier row(s): {', '.join(labels[:5])} and 2 more" in why
    assert labels[5] not in why.split(": ")[-1].split(", ")
    assert "outlier rows (3 sigma): " + ", ".join(labels) in res.summary()
    assert res.to_json()["outliers"] == labels


def test_the_verdict_names_every_outlier_row_when_there_are_five_or_fewer():
    res = _with_bad_rows([17, 33])
    assert res.outliers == [17, 33]
    assert res.verdict[1].endswith(f"2 outlier row(s): {res.labels[17]}, {res.labels[33]}")
