"""The exact planar heading-error model of a level compass, and its nonlinear least-squares fit.

Because a turntable is level, the vertical field ``Z`` is constant over a sweep, so every error source of
:mod:`navlib.sensors.compass` (hard and soft iron, scale, non-orthogonality, mounting misalignment, even
tilt misalignment leaking ``Z`` into x and y) makes the measured horizontal field an affine function of the
true horizontal unit vector ``r(psi) = [cos psi, -sin psi]``: ``m_xy = A r + c``.  Heading sees only the
direction of ``m_xy``, so the overall scale of ``A`` is unobservable and exactly five parameters remain,
written as named physical effects:

    m_xy  ∝  Rot(yaw) [ (I + [[e, f], [f, -e]]) r(psi) + [hx, hy] + k (T - T_ref) ]

``misalignment`` = ``yaw`` (a constant heading offset), ``soft_iron`` = ``(e, f)`` (the symmetric,
trace-free distortion: a two-cycle error), ``hard_iron`` = ``(hx, hy)`` in units of ``H`` (a one-cycle
error), and ``temperature`` = ``k`` (the hard iron's drift with temperature).  This model is *exact* (not a
truncated harmonic series); Archibald Smith's A..E series (:mod:`navlib.methods.smith`) is its first-order
harmonic approximation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from ..angles import heading_deg, wrap_deg
from ..errors import InputError

PLANAR_EFFECTS = {
    "misalignment": ("yaw_deg",),
    "hard_iron": ("hard_x", "hard_y"),
    "soft_iron": ("soft_e", "soft_f"),
    "temperature": ("temp_x_per_c", "temp_y_per_c"),
}


def _rotation(yaw_deg):
    y = np.radians(yaw_deg)
    return np.array([[np.cos(y), np.sin(y)], [-np.sin(y), np.cos(y)]])


@dataclass
class PlanarModel:
    """Exact level-compass heading model (see module docstring)

        m_xy ∝ Rot(yaw) [ (I + [[e, f], [f, -e]]) r(psi) + h + k (T - T_ref) ]

    ``hard_x, hard_y`` (h) are in units of the horizontal field H; ``temp_x_per_c, temp_y_per_c`` (k) are
    the hard iron's drift with temperature, in H per degC, about ``reference_temperature_c``. Effects not in
    ``effects`` are held at zero; the temperature effect needs the temperature of every reading."""

    effects: tuple[str, ...] = ("misalignment", "hard_iron", "soft_iron")
    params: dict = field(default_factory=dict)
    reference_temperature_c: float = 20.0

    def full_params(self) -> dict:
        p = {name: 0.0 for names in PLANAR_EFFECTS.values() for name in names}
        p.update(self.params)
        return p

    def _offset(self, p, n, temperature_c):
        h = np.repeat(np.array([[p["hard_x"]], [p["hard_y"]]]), n, axis=1)
        if p["temp_x_per_c"] or p["temp_y_per_c"]:
            if temperature_c is None:
                raise InputError(
                    "the temperature effect needs the temperature of every reading "
                    "(column 'temperature_c')"
                )
            dt = np.asarray(temperature_c, dtype=float) - self.reference_temperature_c
            h = h + np.array([[p["temp_x_per_c"]], [p["temp_y_per_c"]]]) * dt[None, :]
        return h

    def _field(self, true_deg, temperature_c=None):
        p = self.full_params()
        t = np.radians(np.atleast_1d(np.asarray(true_deg, dtype=float)))
        r = np.stack([np.cos(t), -np.sin(t)])
        S = np.array([[1 + p["soft_e"], p["soft_f"]], [p["soft_f"], 1 - p["soft_e"]]])
        return _rotation(p["yaw_deg"]) @ (S @ r + self._offset(p, len(t), temperature_c))

    def predict_measured(self, true_deg, temperature_c=None) -> np.ndarray:
        """Measured heading (deg, [0, 360)) the model predicts for the true headings."""
        m = self._field(true_deg, temperature_c)
        return heading_deg(m[0], m[1])

    def jacobian(self, true_deg, names, temperature_c=None) -> np.ndarray:
        """d(measured heading)/d(parameter), deg per unit parameter, (N x len(names)), exact: with
        ``v = S r + h + k (T - T_ref)`` the heading is ``atan2(-v_y, v_x) + yaw``, so
        ``d psi_m / d p = (v_y dv_x/dp - v_x dv_y/dp) / |v|^2`` (rad) and ``d psi_m / d yaw = 1``."""
        p = self.full_params()
        t = np.radians(np.atleast_1d(np.asarray(true_deg, dtype=float)))
        r0, r1 = np.cos(t), -np.sin(t)
        S = np.array([[1 + p["soft_e"], p["soft_f"]], [p["soft_f"], 1 - p["soft_e"]]])
        v = S @ np.stack([r0, r1]) + self._offset(p, len(t), temperature_c)
        k = np.degrees(1.0) / np.sum(v * v, axis=0)
        one, zero = np.ones_like(t), np.zeros_like(t)
        dt = (
            np.asarray(temperature_c, dtype=float) - self.reference_temperature_c
            if temperature_c is not None
            else zero
        )
        dv = {
            "soft_e": (r0, -r1),
            "soft_f": (r1, r0),
            "hard_x": (one, zero),
            "hard_y": (zero, one),
            "temp_x_per_c": (dt, zero),
            "temp_y_per_c": (zero, dt),
        }
        cols = [one if n == "yaw_deg" else k * (v[1] * dv[n][0] - v[0] * dv[n][1]) for n in names]
        return np.column_stack(cols) if cols else np.zeros((len(t), 0))

    def predict_error(self, true_deg, temperature_c=None) -> np.ndarray:
        return wrap_deg(
            self.predict_measured(true_deg, temperature_c) - np.asarray(true_deg, dtype=float)
        )

    def correct(self, measured_deg, temperature_c=None) -> np.ndarray:
        """Invert the model: the true heading (deg, [0, 360)) that yields each measured heading.  Solves
        ``|S^-1 (lambda R^-1 u - h)| = 1`` for the positive scale ``lambda`` along the measured direction
        ``u``; the closed form needs ``|h| < 1`` in the S-metric (the compass still sees north)."""
        p = self.full_params()
        a = np.radians(np.atleast_1d(np.asarray(measured_deg, dtype=float)))
        u = np.stack([np.cos(a), -np.sin(a)])
        S = np.array([[1 + p["soft_e"], p["soft_f"]], [p["soft_f"], 1 - p["soft_e"]]])
        Si = np.linalg.inv(S)
        a_vec = Si @ (_rotation(p["yaw_deg"]).T @ u)
        b_vec = Si @ self._offset(p, len(a), temperature_c)
        A = np.sum(a_vec**2, axis=0)
        B = -2 * np.sum(b_vec * a_vec, axis=0)
        C = np.sum(b_vec**2, axis=0) - 1.0
        disc = np.maximum(B**2 - 4 * A * C, 0.0)
        lam = (-B + np.sqrt(disc)) / (2 * A)
        r = lam * a_vec - b_vec
        return heading_deg(r[0], r[1])


def fit_planar_model(
    true_deg,
    measured_deg,
    effects=("misalignment", "hard_iron", "soft_iron"),
    initial: dict | None = None,
    temperature_c=None,
    full_output: bool = False,
):
    """Fit the exact planar model's named effects by nonlinear least squares (scipy ``least_squares``,
    trust-region reflective) on the wrapped heading residual ``wrap(model(true) - measured)``.

    The temperature effect is referred to the mean temperature of the data (so it adds no constant hard
    iron). ``full_output=True`` also returns scipy's result (residuals and Jacobian)."""
    effects = tuple(effects)
    unknown = [e for e in effects if e not in PLANAR_EFFECTS]
    if unknown:
        raise InputError(
            f"unknown compass effect '{unknown[0]}'; known: {', '.join(PLANAR_EFFECTS)}"
        )
    names = [n for e in effects for n in PLANAR_EFFECTS[e]]
    true_deg = np.asarray(true_deg, dtype=float)
    measured_deg = np.asarray(measured_deg, dtype=float)
    if len(true_deg) < len(names) + 1:
        raise InputError(f"{len(true_deg)} readings cannot determine {len(names)} model parameters")
    t_ref = 20.0
    if "temperature" in effects:
        if temperature_c is None:
            raise InputError("the temperature effect needs the column 'temperature_c'")
        temperature_c = np.asarray(temperature_c, dtype=float)
        t_ref = float(np.mean(temperature_c))
    x0 = np.array([(initial or {}).get(n, 0.0) for n in names])
    if "yaw_deg" in names and not initial:
        x0[names.index("yaw_deg")] = float(
            np.degrees(np.angle(np.mean(np.exp(1j * np.radians(measured_deg - true_deg)))))
        )

    def resid(x):
        model = PlanarModel(effects, dict(zip(names, x)), t_ref)
        return wrap_deg(model.predict_measured(true_deg, temperature_c) - measured_deg)

    lo = np.array([-180.0 if n == "yaw_deg" else -0.95 for n in names])
    hi = -lo
    if not names:
        model = PlanarModel(effects, {}, t_ref)
        return (model, None) if full_output else model
    sol = least_squares(
        resid, np.clip(x0, lo + 1e-9, hi - 1e-9), bounds=(lo, hi), x_scale="jac", method="trf"
    )
    model = PlanarModel(effects, dict(zip(names, map(float, sol.x))), t_ref)
    return (model, sol) if full_output else model
