"""The plain magnetometer calibration a dedicated calibrator does: fit an ellipsoid to the raw field.

A magnetometer with hard iron ``b`` and soft iron and scale errors reads ``m = W u + b`` where the true field
``u`` has a constant magnitude ``F``; so ``m`` lies on the ellipsoid ``|S (m - b)| = F`` with ``S`` the
symmetric square root of ``(W W')^-1`` (the rotation part of ``W`` cannot be seen without a reference).

* :func:`algebraic_ellipsoid` -- the linear least-squares fit of the quadric
  ``m' Q m + 2 v' m = 1`` (9 coefficients), centre ``b = -Q^-1 v``, shape ``S = sqrt(Q / (1 + b' Q b))``
  (Fitzgibbon-style direct fit without the ellipsoid constraint; e.g. Li and Griffiths 2004).  Fast, but it
  minimises an algebraic, not a geometric, error.
* :func:`lm_ellipsoid` -- Levenberg-Marquardt on the 9 parameters of ``b`` and symmetric ``S``, residual
  ``|S (m - b)| - F`` with ``F`` fixed to the mean radius of the algebraic start, as calibration tools such
  as magcc do (``scipy.optimize.least_squares(method="lm")``).

These are the peers the workbench's reference-free calibration (:mod:`navlib.workbench.calibration`) is
measured against (``benchmarks/calibrate_peer.py``, the workbench chapter): they fit every file and give
no uncertainty, no noise model and no refusal.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from ..errors import InputError


def _field(m) -> np.ndarray:
    m = np.asarray(m, float)
    if m.ndim != 2 or m.shape[1] != 3 or len(m) < 9:
        raise InputError(
            f"an ellipsoid fit needs an (n, 3) field with n >= 9 rows, got shape {m.shape}"
        )
    if not np.all(np.isfinite(m)):
        raise InputError("an ellipsoid fit needs a finite field (NaN or infinity found)")
    return m


def algebraic_ellipsoid(m) -> tuple[np.ndarray, np.ndarray]:
    """``(b, S)`` of the algebraic fit (module docstring): ``|S (m - b)| = 1`` on the fitted quadric.
    InputError when the quadric is not an ellipsoid (the field's directions do not span 3-D)."""
    m = _field(m)
    x, y, z = m.T
    D = np.column_stack([x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, 2 * x, 2 * y, 2 * z])
    c = np.linalg.lstsq(D, np.ones(len(m)), rcond=None)[0]
    Q = np.array([[c[0], c[3], c[4]], [c[3], c[1], c[5]], [c[4], c[5], c[2]]])
    try:
        b = -np.linalg.solve(Q, c[6:])
    except np.linalg.LinAlgError:
        raise InputError(
            "the field's quadric is singular: the directions do not span 3-D"
        ) from None
    w, V = np.linalg.eigh(Q / (1.0 + b @ Q @ b))
    if np.any(w <= 0):
        raise InputError("the fitted quadric is not an ellipsoid: the directions do not span 3-D")
    return b, V @ np.diag(np.sqrt(w)) @ V.T


def lm_ellipsoid(m) -> tuple[np.ndarray, np.ndarray, float]:
    """``(b, S, F)`` of the Levenberg-Marquardt fit (module docstring): the corrected field is
    ``(m - b) S`` (rows; ``S`` symmetric) with magnitude ``F`` (uT, the algebraic start's mean radius)."""
    m = _field(m)
    b0, S0 = algebraic_ellipsoid(m)
    F = float(np.mean(np.linalg.norm(m - b0, axis=1)))
    iu = np.triu_indices(3)

    def unpack(p):
        S = np.zeros((3, 3))
        S[iu] = p[3:]
        return p[:3], S + np.triu(S, 1).T

    def resid(p):
        b, S = unpack(p)
        return np.linalg.norm((m - b) @ S, axis=1) - F

    fit = least_squares(resid, np.concatenate([b0, (S0 * F)[iu]]), method="lm")
    b, S = unpack(fit.x)
    return b, S, F
