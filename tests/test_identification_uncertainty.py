"""The predicted error of a position: per axis, 3D RMS, 95 % radius, and the model error."""

import math

import numpy as np
import pytest
from identification_helpers import configurations, measure, perturbed, truth_chain
from scipy.stats import chi2

from robotcell import load_robot
from robotcell.errors import InputError
from robotcell.identification import TargetMeasurements, identify
from robotcell.identification.uncertainty import (
    PredictedError,
    error_radius,
    position_error,
    position_sigma,
)
from robotcell.kinematics.covariance import ParameterCovariance
from robotcell.robot.models import load_robot as load_model
from robotcell.robot.models import save_robot


def test_the_95_percent_radius_is_the_quantile_of_the_error_length():
    # isotropic and one-dimensional errors in closed form; anisotropic ones against a Monte
    # Carlo of a million samples
    assert error_radius(np.eye(3) * 4.0) == pytest.approx(2.0 * math.sqrt(chi2.ppf(0.95, 3)),
                                                          rel=1e-6)
    assert error_radius(np.diag([1.0, 0.0, 0.0])) == pytest.approx(1.959964, rel=1e-5)
    assert error_radius(np.zeros((3, 3))) == 0.0
    rng = np.random.default_rng(0)
    lam = np.array([[1.0, 0.5, 0.1], [3.0, 2.0, 1.0], [1.0, 1e-3, 1e-6]])
    z = rng.standard_normal((1_000_000, 3))
    mc = np.sqrt(np.quantile((z**2) @ lam.T, 0.95, axis=0))
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]  # in any axes
    S = np.einsum("ij,nj,kj->nik", R, lam, R)
    assert np.allclose(error_radius(S), mc, rtol=2e-3)
    assert np.allclose(error_radius(S, 0.5), np.sqrt(np.quantile((z**2) @ lam.T, 0.5, axis=0)),
                       rtol=2e-3)
    e = PredictedError(S)
    assert np.allclose(e.rms**2, lam.sum(axis=1))
    assert np.allclose(np.sum(e.per_axis**2, axis=1), lam.sum(axis=1))
    with pytest.raises(InputError, match="probability must be between 0 and 1"):
        error_radius(np.eye(3), 1.0)
    with pytest.raises(InputError, match=r"shape \(..., 3, 3\)"):
        error_radius(np.eye(2))


def _kr16(noise, unmodelled=0.0, n=80, seed=5):
    """A KR 16 measured with ``noise`` (m) and, on top, a scatter the model cannot explain."""
    rng = np.random.default_rng(seed)
    nominal = load_robot("kuka_kr16")
    ch, x = truth_chain(perturbed(nominal, rng), 1, False, rng)
    meas = measure(ch, x, configurations(nominal, n, rng), rng, noise)
    shaken = meas.points + rng.normal(0.0, unmodelled, meas.points.shape)
    return nominal, TargetMeasurements(meas.q, shaken)


def test_the_model_error_is_the_scatter_beyond_the_stated_accuracy():
    # 0.02 mm noise stated as such: no model error; the same data with 0.05 mm more scatter
    # than stated: the model error is that scatter (per coordinate)
    nominal, meas = _kr16(0.02e-3)
    res = identify(nominal, meas, sigma=0.02e-3)
    assert res.unexplained == pytest.approx(0.02e-3, rel=0.25)
    assert res.model_error < 0.012e-3
    nominal, meas = _kr16(0.02e-3, 0.05e-3)
    res = identify(nominal, meas, sigma=0.02e-3)
    assert res.model_error == pytest.approx(0.05e-3, rel=0.25)
    assert res.robot.covariance.model_error == res.model_error
    # a stated accuracy above the scatter: no model error, the measurement part is the scatter
    res = identify(nominal, meas, sigma=0.2e-3)
    assert res.model_error == 0.0 and res.unexplained < 0.1e-3
    q = meas.q[:5]
    true_error = res.predicted_error(q).rms
    measured = res.predicted_error(q, measured=True).rms
    assert np.all(measured**2 == pytest.approx(true_error**2 + 3 * res.unexplained**2))


def test_the_tcp_error_carries_the_base_and_the_model_error(tmp_path):
    nominal, meas = _kr16(0.02e-3, 0.05e-3)
    res = identify(nominal, meas, sigma=0.02e-3)
    cov = res.robot.covariance
    assert cov.names[:6] == ("base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz")
    q = meas.q[:10]
    tool = np.eye(4)
    tool[:3, 3] = [0.0, 0.0, 0.2]
    err = position_error(res.robot, q, tool)
    links = [i for i, n in enumerate(cov.names) if not n.startswith("base.")]
    only_links = ParameterCovariance(tuple(cov.names[i] for i in links),
                                     cov.matrix[np.ix_(links, links)])
    from dataclasses import replace

    narrow = position_sigma(replace(res.robot, covariance=only_links), q, tool)
    assert np.all(err.rms > narrow)
    assert np.all(err.rms**2 >= 3 * cov.model_error**2)
    assert np.allclose(err.rms, position_sigma(res.robot, q, tool))
    assert np.all(err.radius() > err.rms)
    # the model file keeps both
    save_robot(res.robot, tmp_path / "arm.yaml")
    assert "model_error:" in (tmp_path / "arm.yaml").read_text()
    back = load_model(tmp_path / "arm.yaml").covariance
    assert back.model_error == pytest.approx(cov.model_error, rel=1e-5)
    assert np.allclose(position_sigma(load_model(tmp_path / "arm.yaml"), q, tool), err.rms,
                       rtol=1e-5)


def test_a_model_file_with_a_bad_model_error_is_refused(tmp_path):
    text = ("name: a\nconvention: standard\njoints:\n  - {type: revolute, a: 100, alpha: 0, d: 0, theta: 0}\n"
            "covariance: {parameters: [A1.a], matrix: [[0.01]], model_error: -1}\n")
    (tmp_path / "a.yaml").write_text(text)
    with pytest.raises(InputError, match="the model error must be a length >= 0"):
        load_model(tmp_path / "a.yaml")
    (tmp_path / "b.yaml").write_text(text.replace("A1.a]", "base.q]"))
    with pytest.raises(InputError, match=r"base\.<x\|y\|z\|rx\|ry\|rz>"):
        load_model(tmp_path / "b.yaml")
