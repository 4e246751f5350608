"""The local field a reference-free magnetometer fit estimates, beside the IGRF-14 model at the recording's site.

:func:`field_check` compares the fitted intensity (and dip, with an accelerometer) with the model
(:func:`model_field`, :mod:`navlib.sensors.earth_field`) within the fit's uncertainty
(:func:`parameter_covariance`: ``s^2 (J'J)^-1``, whitened under correlated noise) plus the crustal field
and the sensor's scale tolerance; :func:`field_lines` gives it as report lines.  Used by the calibration
(:func:`navlib.workbench.calibration.calibrate`), the reference-free loop's final check
(:mod:`navlib.workbench.magnetometer_free`) and ``navlib field``.
"""

from __future__ import annotations

import numpy as np

from ..errors import check_param
from ..sensors.earth_field import Site, igrf_field


def parameter_covariance(fit, noise=None) -> tuple[list, np.ndarray]:
    """``(names, cov)``: the covariance of ``fit``'s parameters, ``s^2 (J'J)^-1`` with ``s^2 = RSS / (n - p)``,
    on the whitened residual and Jacobian when ``noise`` (a :class:`navlib.workbench.serial.NoiseModel`)
    is correlated (generalised least squares)."""
    J, r = fit.jacobian, fit.residuals
    if noise is not None and noise.correlated:
        J, r = noise.whiten(J), noise.whiten(r)
    s2 = float(r @ r) / max(fit.n - fit.n_params, 1)
    return list(fit.params), s2 * np.linalg.pinv(J.T @ J, hermitian=True)


#: Tolerances of the comparison with the model field (:func:`field_check`): the crustal field IGRF leaves
#: out (typically up to a few hundred nT away from magnetic rocks: Alken et al. 2021) and the sensor's
#: absolute scale, which the invariants cannot calibrate (the mean scale trades against the intensity) --
#: a free choice, stated: 1 % unless the user gives another.
CRUST_TOL_UT = 0.3
SCALE_TOL = 0.01


#: How far from a geographic pole (deg of latitude, about 1 cm) :func:`model_field` evaluates the field it
#: reports at the pole: the limit of horizontal, down, intensity and dip (they change by about 1e-9 of their
#: value over that distance; at the pole itself ppigrf divides by sin(colatitude) = 0 and returns NaN).
POLE_STEP_DEG = 1e-7
#: What :func:`model_field` says at a geographic pole instead of a declination.
POLE_NOTE = (
    "at a geographic pole the directions north and east are undefined, and so is the declination; "
    "horizontal, down, intensity and dip are the field's limits at the pole"
)


def model_field(site) -> dict:
    """The IGRF-14 field at ``site`` (:class:`navlib.sensors.earth_field.Site`) as a JSON-ready dict
    (``EarthField.to_dict`` of :mod:`navlib.sensors.earth_field`), finite everywhere: at a geographic pole
    (``|lat_deg| = 90``) ``north_ut``, ``east_ut`` and ``declination_deg`` are None, ``note`` says why
    (:data:`POLE_NOTE`), and the other values are the limits at the pole (:data:`POLE_STEP_DEG`)."""
    if abs(site.lat_deg) < 90.0:
        return igrf_field(site).to_dict()
    near = Site(
        float(np.copysign(90.0 - POLE_STEP_DEG, site.lat_deg)),
        site.lon_deg,
        site.height_m,
        site.date,
    )
    out = igrf_field(near).to_dict()
    out.update(north_ut=None, east_ut=None, declination_deg=None, note=POLE_NOTE)
    return out


def field_check(fit, site=None, noise=None, scale_tol: float = SCALE_TOL) -> dict:
    """The local field the reference-free fit estimates beside the IGRF-14 model at ``site``
    (:class:`navlib.sensors.earth_field.Site`), and whether they differ beyond the uncertainty.

    Intensity: estimate +- 1.96 sigma (parameter covariance, :func:`parameter_covariance`); anomaly when
    ``|F - F_model| > 1.96 sigma + CRUST_TOL_UT + scale_tol F_model``.  Dip (with an accelerometer; free of
    the sensor's scale): anomaly when ``|dip - dip_model| > 1.96 sigma + deg(CRUST_TOL_UT / F_model)``.
    Without a site only the estimate is returned."""
    check_param("scale_tol", scale_tol, lo=0, hi=0.5)
    names, cov = parameter_covariance(fit, noise)
    iF = names.index("field_ut")
    F = fit.params["field_ut"]
    out = {"intensity_ut": F, "intensity_std_ut": float(np.sqrt(cov[iF, iF]))}
    if "field_down_ut" in fit.params:
        iD = names.index("field_down_ut")
        D = fit.params["field_down_ut"]
        x = float(np.clip(-D / F, -1, 1))
        g = np.zeros(len(names))  # d dip / d(F, D), rad
        k = 1.0 / np.sqrt(max(1 - x * x, 1e-12))
        g[iF], g[iD] = k * D / F**2, -k / F
        out["dip_deg"] = float(np.degrees(np.arcsin(x)))
        out["dip_std_deg"] = float(np.degrees(np.sqrt(g @ cov @ g)))
    if site is None:
        return out
    model = model_field(site)
    model_f, model_dip = model["intensity_ut"], model["dip_deg"]
    out["model"] = {
        "name": "IGRF-14 (ppigrf)",
        "lat_deg": site.lat_deg,
        "lon_deg": site.lon_deg,
        "height_m": site.height_m,
        "date": str(site.date),
        "intensity_ut": model_f,
        "dip_deg": model_dip,
        "declination_deg": model["declination_deg"],
        **({"note": model["note"]} if "note" in model else {}),
    }
    tol_f = 1.96 * out["intensity_std_ut"] + CRUST_TOL_UT + scale_tol * model_f
    out["intensity_difference_ut"] = F - model_f
    out["intensity_tolerance_ut"] = tol_f
    anomalies = []
    if abs(F - model_f) > tol_f:
        anomalies.append(
            f"intensity {F:.2f} uT against the model's {model_f:.2f} uT (beyond +-{tol_f:.2f} uT)"
        )
    if "dip_deg" in out:
        tol_d = 1.96 * out["dip_std_deg"] + float(np.degrees(CRUST_TOL_UT / model_f))
        out["dip_difference_deg"] = out["dip_deg"] - model_dip
        out["dip_tolerance_deg"] = tol_d
        if abs(out["dip_difference_deg"]) > tol_d:
            anomalies.append(
                f"dip {out['dip_deg']:.2f} deg against the model's {model_dip:.2f} deg "
                f"(beyond +-{tol_d:.2f} deg)"
            )
    out["local_anomaly"] = bool(anomalies)
    out["message"] = (
        "local anomaly: " + "; ".join(anomalies) + " (steel or magnets nearby, or a sensor scale "
        "error beyond the tolerance)"
        if anomalies
        else "the local field agrees with the model within the uncertainty"
    )
    return out


def field_lines(check: dict) -> list[str]:
    """The field check as report lines."""
    est = f"estimated local field: intensity {check['intensity_ut']:.2f} +- {1.96 * check['intensity_std_ut']:.2f} uT"
    if "dip_deg" in check:
        est += f", dip {check['dip_deg']:.2f} +- {1.96 * check['dip_std_deg']:.2f} deg"
    lines = [est + " (95 %)"]
    if "model" in check:
        m = check["model"]
        lines.append(
            f"model ({m['name']} at {m['lat_deg']:g}, {m['lon_deg']:g}, {m['height_m']:g} m, {m['date']}): "
            f"intensity {m['intensity_ut']:.2f} uT, dip {m['dip_deg']:.2f} deg"
        )
        lines.append(check["message"])
    return lines
