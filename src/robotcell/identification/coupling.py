"""Whether the data support a stated J2/J3 coupling: the fits with and without it, in mm.

A controller whose axis 3 counts the forearm's angle to the horizontal (a parallel linkage)
couples the chain's joint 3 to axis 2: ``q3_model = J3 + k * J2``. The sign is the
ROS-Industrial drivers': FANUC ``k = +1`` (``fanuc_driver`` ``linkage_transform``, ``J3_out = J3_in
+ J23_factor * J2_in``, with ``J23_factor = 1`` in the launch files of the M-20iA and the LR Mate
200iD; the library models state ``coupling: {j23_factor: 1}``, docs/robots.md), the ABB IRB 2400
``k = -1``. A wrong sign or factor moves the forearm by the whole angle of axis 2: hundreds of
millimetres.

:func:`coupling_check` fits three times: with ``k`` held, with ``k = 0`` held (no coupling) and
with ``k`` free. The coupling explains ``rms_without - rms_fitted`` (hundreds of mm on a real
arm). The stated ``k`` is supported when holding it costs, against the fitted factor, no more
than a practical tolerance in mm (:func:`practical_tolerance`): 0.1 % of what the coupling
explains, or the stated point accuracy, or a tenth of the fitted RMS, whichever is largest. A
factor's statistical sigma alone is no test: on hundreds of rows it is 1e-4, and an arm whose
axis 3 has a small gear-ratio error or bends under its weight fits a factor of 0.9988 +- 0.0002
to data that ``k = 1`` fits to their own scatter (a real linkage's factor is exactly +-1; the
last digits take up what the model does not explain, and ``--scale`` identifies a gear ratio).
"""

from __future__ import annotations

from typing import Any

from robotcell.identification.engine import identify
from robotcell.identification.measurements import TargetMeasurements
from robotcell.identification.result import IdentificationResult
from robotcell.robot.robot import Robot

__all__ = ["coupling_check", "identify_with_coupling", "practical_tolerance"]

#: Share of what the coupling explains by which the fit with the stated factor may exceed the fit
#: with the factor free ...
EXPLAINED_SHARE = 0.001
#: ... or share of the free fit's own RMS.
RMS_SHARE = 0.1


def practical_tolerance(sigma: float, rms_free: float, rms_without: float) -> float:
    """How much larger (RMS, m) the fit with the stated factor may be than with it fitted.

    Parameters
    ----------
    sigma : float
        Stated accuracy of a measured coordinate (m).
    rms_free : float
        RMS position error of the fit with the factor free (m).
    rms_without : float
        RMS position error of the fit without coupling, ``k = 0`` (m).

    Returns
    -------
    float
        ``max(EXPLAINED_SHARE * (rms_without - rms_free), sigma, RMS_SHARE * rms_free)``
        (m).
    """
    return max(EXPLAINED_SHARE * (rms_without - rms_free), sigma, RMS_SHARE * rms_free)


def coupling_check(nominal: Robot, measurements: TargetMeasurements, k: float,
                   with_k: IdentificationResult, **options: Any) -> dict[str, Any]:
    """Compare the fit with the stated J2/J3 factor with the fits without it and with it free.

    Parameters
    ----------
    nominal : Robot
    measurements : TargetMeasurements
    k : float
        Stated factor: ``q3_model = J3 + k * J2`` (FANUC: +1, see the module).
    with_k : IdentificationResult
        The identification with ``k`` held.
    **options
        Passed to :func:`~robotcell.identification.identify` (accuracies, ``scale``, ...,
        ``options``); its ``j23_factor``, ``fit_j23_factor`` and ``hold`` are this check's own.

    Returns
    -------
    dict
        ``k``, ``rms_with_mm``, ``rms_without_mm`` (``k = 0``), ``rms_fitted_mm`` (``k`` free),
        ``k_fitted``, ``k_sigma``, ``tolerance_mm``, ``supported`` and a ``verdict`` sentence.
    """
    options = {n: v for n, v in options.items() if n not in ("j23_factor", "fit_j23_factor", "hold")}
    without = identify(nominal, measurements, j23_factor=0.0, fit_j23_factor=False, **options)
    free = identify(nominal, measurements, j23_factor=k, fit_j23_factor=True, **options)
    p = free.parameter("j23_factor")
    rms_with, rms_without, rms_free = with_k.rms_after, without.rms_after, free.rms_after
    tol = practical_tolerance(with_k.touch_sigma, rms_free, rms_without)
    supported = rms_with - rms_free <= tol
    fitted = (f"fitted k = {p.value:.5f} +- {p.sigma:.2g}" if p.free
              else "k cannot be fitted from these rows")
    if supported:
        verdict = (f"the data support k = {k:g}: RMS {rms_with * 1e3:.4f} mm with it, "
                   f"{rms_without * 1e3:.4f} mm without; the {fitted} fits "
                   f"{max(rms_with - rms_free, 0.0) * 1e3:.4f} mm better, within the "
                   f"{tol * 1e3:.4f} mm tolerance")
    else:
        verdict = (f"the data do not support k = {k:g}: RMS {rms_with * 1e3:.4f} mm with it, "
                   f"{rms_free * 1e3:.4f} mm with the {fitted}, {rms_without * 1e3:.4f} mm "
                   "without; check the controller's J2/J3 convention (FANUC: +1, docs/robots.md)")
    return {"k": k, "rms_with_mm": rms_with * 1e3, "rms_without_mm": rms_without * 1e3,
            "rms_fitted_mm": rms_free * 1e3, "k_fitted": p.value, "k_sigma": p.sigma,
            "tolerance_mm": tol * 1e3, "supported": supported, "verdict": verdict}


def identify_with_coupling(nominal: Robot, measurements: TargetMeasurements, k: float,
                           **options: Any) -> IdentificationResult:
    """Identify with a stated J2/J3 coupling ``k`` and say whether the data support it.

    Parameters
    ----------
    nominal : Robot
    measurements : TargetMeasurements
    k : float
        Stated factor: ``q3_model = J3 + k * J2`` (FANUC: +1, the forearm's angle to the
        horizontal; see the module).
    **options
        Passed to :func:`~robotcell.identification.identify` (accuracies, ``scale``,
        ``rank_tol``, ``max_sigma_length``, ``max_sigma_angle``, ``name``).

    Returns
    -------
    IdentificationResult
        The fit with ``k`` held; its ``coupling_check`` is :func:`coupling_check`'s.
    """
    with_k = identify(nominal, measurements, j23_factor=k, **options)
    with_k.coupling_check = coupling_check(nominal, measurements, k, with_k, **options)
    return with_k
