"""The reference-free magnetometer invariants on plain arrays, with their analytic Jacobian (the inner loop
of :mod:`navlib.workbench.magnetometer_free`'s fit; issue 34: the fit once spent 90 % of its time in
pandas column lookups and finite differences).

With the offset ``o = b + k (T - T_c)``, ``v = m - o``, the correction ``M = I + K`` (symmetric, ``K``
trace-free: ``diag(s_x, s_y, -s_x - s_y)`` and the soft-iron terms) and ``u = M v``::

    e_0 = |u| - F
    g   = (R^T a/|a|) . u - D                     (R: the misalignment rotation)
    c   = clip(D / F, -0.99, 0.99),  s = sqrt(1 - c^2)
    e_1 = (g - c e_0) / s

and, for any parameter ``q`` that moves ``u``: ``de_0/dq = (u/|u|) . du/dq``, ``dg/dq = (R^T a/|a|) . du/dq``,
with ``du/db_j = -M e_j``, ``du/dk_j = -(T - T_c) M e_j`` and ``du/dK = dK v``.  The field parameters move
``e_1`` through ``c`` too: ``de_1/dc = -e_0/s + (g - c e_0) c / s^3``, ``dc/dF = -D/F^2``, ``dc/dD = 1/F``
(zero where ``c`` is clipped).  The misalignment angles' columns differentiate the rotation matrix by central differences
(step 1e-4 deg).
Rows are interleaved as the fit's residual vector is: ``[e_0, e_1]`` of row 0, then of row 1, and so on.

The residuals and the Jacobian are computed row by row in one compiled loop (``_invariants``, numba;
a fit evaluates them tens of times, and the numpy formulation spent most of its time allocating (n, 3)
temporaries); :meth:`FreeKernel.reference_residuals` and :meth:`FreeKernel.reference_jacobian` are the
numpy formulation the tests compare it with (equal to rounding).
"""

from __future__ import annotations

import numpy as np
from numba import njit

CLIP = 0.99
# d K / d parameter, the trace-free symmetric part of the correction
_DK = {
    "scale_x": np.diag([1.0, 0.0, -1.0]),
    "scale_y": np.diag([0.0, 1.0, -1.0]),
    "soft_xy": np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, 0]]),
    "soft_xz": np.array([[0.0, 0, 1], [0, 0, 0], [1, 0, 0]]),
    "soft_yz": np.array([[0.0, 0, 0], [0, 0, 1], [0, 1, 0]]),
}
_HARD = ("hard_x_ut", "hard_y_ut", "hard_z_ut")
_TEMP = ("temp_x_ut_c", "temp_y_ut_c", "temp_z_ut_c")
_MIS = ("mis_x_deg", "mis_y_deg", "mis_z_deg")
MIS_STEP_DEG = 1e-4


def rotation_deg(rotvec_deg) -> np.ndarray:
    """The rotation matrix of a rotation vector in degrees (Rodrigues' formula; scipy's
    ``Rotation.from_rotvec(np.radians(v)).as_matrix()`` without its per-call overhead)."""
    v = np.radians(np.asarray(rotvec_deg, float))
    th = float(np.sqrt(v @ v))
    if th == 0.0:
        return np.eye(3)
    K = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]) / th
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


# column kinds of the compiled kernel
_K_DK, _K_HARD, _K_TEMP, _K_FIELD, _K_DOWN, _K_MIS, _K_NONE = range(7)
_DK_STACK = np.stack(list(_DK.values()))


@njit(error_model="numpy", cache=True)
def _invariants(m, ahat, dt, M, o, kt, R, F, D, kinds, which, dks, dRs, want_jac):
    """The residuals (n, k) and, with ``want_jac``, the Jacobian (n k, p) of the module docstring, row by
    row; ``ahat`` (n, 3) or (0, 3) without an accelerometer, ``dt`` (n,) or (0,); column ``j`` of the
    Jacobian is of kind ``kinds[j]`` (``_K_*``) and index ``which[j]`` (into ``dks``, the axes, ``dRs``)."""
    n = m.shape[0]
    acc = ahat.shape[0] > 0
    has_dt = dt.shape[0] > 0
    k = 2 if acc else 1
    p = kinds.shape[0]
    res = np.empty((n, k))
    J = np.zeros((n * k if want_jac else 0, p))
    raw = D / max(F, 1e-9)
    c = min(max(raw, -0.99), 0.99)
    s = np.sqrt(1.0 - c * c)
    free = abs(raw) < 0.99 and F > 1e-9
    v = np.empty(3)
    u = np.empty(3)
    at = np.empty(3)
    du = np.empty(3)
    for i in range(n):
        for a in range(3):
            v[a] = m[i, a] - o[a]
            if has_dt:
                v[a] -= dt[i] * kt[a]
        for a in range(3):
            u[a] = v[0] * M[0, a] + v[1] * M[1, a] + v[2] * M[2, a]
        r = np.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
        e0 = r - F
        res[i, 0] = e0
        g = 0.0
        if acc:
            for a in range(3):
                at[a] = ahat[i, 0] * R[0, a] + ahat[i, 1] * R[1, a] + ahat[i, 2] * R[2, a]
            g = at[0] * u[0] + at[1] * u[1] + at[2] * u[2] - D
            res[i, 1] = (g - c * e0) / s
        if not want_jac:
            continue
        de1_dc = -e0 / s + (g - c * e0) * c / s**3
        for j in range(p):
            kind = kinds[j]
            w = which[j]
            moves_u = True
            if kind == _K_DK:
                for a in range(3):
                    du[a] = v[0] * dks[w, 0, a] + v[1] * dks[w, 1, a] + v[2] * dks[w, 2, a]
            elif kind == _K_HARD:
                for a in range(3):
                    du[a] = -M[w, a]
            elif kind == _K_TEMP:
                for a in range(3):
                    du[a] = -(dt[i] if has_dt else 0.0) * M[w, a]
            else:
                moves_u = False
            if moves_u:
                j0 = (u[0] * du[0] + u[1] * du[1] + u[2] * du[2]) / r
                J[i * k, j] = j0
                if acc:
                    jg = at[0] * du[0] + at[1] * du[1] + at[2] * du[2]
                    J[i * k + 1, j] = (jg - c * j0) / s
            elif kind == _K_FIELD:
                J[i * k, j] = -1.0
                if acc:
                    J[i * k + 1, j] = c / s + (de1_dc * (-D / (F * F)) if free else 0.0)
            elif kind == _K_DOWN:
                if acc:
                    J[i * k + 1, j] = -1.0 / s + (de1_dc / F if free else 0.0)
            elif kind == _K_MIS and acc:
                t = 0.0
                for a in range(3):
                    t += (
                        ahat[i, 0] * dRs[w, 0, a]
                        + ahat[i, 1] * dRs[w, 1, a]
                        + ahat[i, 2] * dRs[w, 2, a]
                    ) * u[a]
                J[i * k + 1, j] = t / s
    return res, J


class FreeKernel:
    """The invariants of one data set for the parameter vector ``x`` named ``names``.

    ``m``: (n, 3) field, uT; ``a``: (n, 3) acceleration or None; ``dt``: (n,) ``T - T_c`` or None."""

    def __init__(
        self, names, m: np.ndarray, a: np.ndarray | None = None, dt: np.ndarray | None = None
    ):
        self.names = list(names)
        self.index = {q: i for i, q in enumerate(self.names)}
        self.m = np.asarray(m, float)
        self.ahat = None if a is None else a / np.linalg.norm(a, axis=1, keepdims=True)
        self.dt = None if dt is None else np.asarray(dt, float)
        self.k = 1 if a is None else 2
        # the compiled loop's inputs: contiguous arrays, empty where absent, and each column's kind
        self.m = np.ascontiguousarray(self.m)
        self._ahat = np.zeros((0, 3)) if self.ahat is None else np.ascontiguousarray(self.ahat)
        self._dt = np.zeros(0) if self.dt is None else np.ascontiguousarray(self.dt)
        kinds, which = [], []
        for q in self.names:
            if q in _DK:
                kinds.append(_K_DK), which.append(list(_DK).index(q))
            elif q in _HARD:
                kinds.append(_K_HARD), which.append(_HARD.index(q))
            elif q in _TEMP:
                kinds.append(_K_TEMP), which.append(_TEMP.index(q))
            elif q == "field_ut":
                kinds.append(_K_FIELD), which.append(0)
            elif q == "field_down_ut":
                kinds.append(_K_DOWN), which.append(0)
            elif q in _MIS:
                kinds.append(_K_MIS), which.append(_MIS.index(q))
            else:
                kinds.append(_K_NONE), which.append(0)
        self._kinds = np.array(kinds, np.int64)
        self._which = np.array(which, np.int64)

    def _get(self, x, q: str) -> float:
        i = self.index.get(q)
        return 0.0 if i is None else float(x[i])

    def _matrix(self, x) -> np.ndarray:
        """``M = I + K`` (module docstring)."""
        sx, sy = self._get(x, "scale_x"), self._get(x, "scale_y")
        xy, xz, yz = self._get(x, "soft_xy"), self._get(x, "soft_xz"), self._get(x, "soft_yz")
        return np.array([[1.0 + sx, xy, xz], [xy, 1.0 + sy, yz], [xz, yz, 1.0 - sx - sy]])

    def _parts(self, x):
        M = self._matrix(x)
        o = np.array([self._get(x, q) for q in _HARD])
        v = self.m - o
        kt = np.array([self._get(x, q) for q in _TEMP])
        if self.dt is not None and np.any(kt):
            v = v - self.dt[:, None] * kt
        u = v @ M  # M symmetric: rows of (M v)
        return M, v, u

    def _rotation(self, x) -> np.ndarray:
        return rotation_deg([self._get(x, q) for q in _MIS])

    def _rotation_steps(self, x) -> np.ndarray:
        """(3, 3, 3): the rotation's derivative with respect to each misalignment angle in the model
        (central difference of :func:`rotation_deg`, step ``MIS_STEP_DEG``; zeros for the others)."""
        dRs = np.zeros((3, 3, 3))
        mis = [self._get(x, q) for q in _MIS]
        for j, q in enumerate(_MIS):
            if q in self.index:
                up, dn = list(mis), list(mis)
                up[j] += MIS_STEP_DEG
                dn[j] -= MIS_STEP_DEG
                dRs[j] = (rotation_deg(up) - rotation_deg(dn)) / (2 * MIS_STEP_DEG)
        return dRs

    def _compiled(self, x, want_jac: bool):
        M = self._matrix(x)
        o = np.array([self._get(x, q) for q in _HARD])
        kt = np.array([self._get(x, q) for q in _TEMP])
        R = self._rotation(x)
        dRs = self._rotation_steps(x) if want_jac and self.ahat is not None else np.zeros((3, 3, 3))
        return _invariants(
            self.m,
            self._ahat,
            self._dt,
            M,
            o,
            kt,
            R,
            self._get(x, "field_ut"),
            self._get(x, "field_down_ut"),
            self._kinds,
            self._which,
            _DK_STACK,
            dRs,
            want_jac,
        )

    def residuals(self, x) -> np.ndarray:
        """(n, k): the invariants' misfit (module docstring)."""
        return self._compiled(x, False)[0]

    def jacobian(self, x) -> np.ndarray:
        """(n k, p): d(residuals().ravel())/dx (module docstring)."""
        return self._compiled(x, True)[1]

    def reference_residuals(self, x) -> np.ndarray:
        """:meth:`residuals` in numpy (the reference the compiled loop is tested against)."""
        _, _, u = self._parts(x)
        r = np.sqrt(np.einsum("ij,ij->i", u, u))
        e0 = r - self._get(x, "field_ut")
        if self.ahat is None:
            return e0[:, None]
        F, D = self._get(x, "field_ut"), self._get(x, "field_down_ut")
        g = np.einsum("ij,ij->i", self.ahat @ self._rotation(x), u) - D
        c = float(np.clip(D / max(F, 1e-9), -CLIP, CLIP))
        return np.column_stack([e0, (g - c * e0) / np.sqrt(1.0 - c * c)])

    def reference_jacobian(self, x) -> np.ndarray:
        """:meth:`jacobian` in numpy (the reference the compiled loop is tested against)."""
        M, v, u = self._parts(x)
        n, p = len(u), len(self.names)
        r = np.sqrt(np.einsum("ij,ij->i", u, u))
        uh = u / r[:, None]
        J0 = np.zeros((n, p))
        acc = self.ahat is not None
        if acc:
            at = self.ahat @ self._rotation(x)
            Jg = np.zeros((n, p))
        for q, i in self.index.items():
            if q in _DK:
                du = v @ _DK[q]
            elif q in _HARD:
                du = np.broadcast_to(-M[_HARD.index(q)], u.shape)
            elif q in _TEMP:
                du = -np.outer(self.dt if self.dt is not None else np.zeros(n), M[_TEMP.index(q)])
            else:
                continue
            J0[:, i] = np.einsum("ij,ij->i", uh, du)
            if acc:
                Jg[:, i] = np.einsum("ij,ij->i", at, du)
        if "field_ut" in self.index:
            J0[:, self.index["field_ut"]] = -1.0
        if not acc:
            return J0
        F, D = self._get(x, "field_ut"), self._get(x, "field_down_ut")
        e0 = r - F
        g = np.einsum("ij,ij->i", at, u) - D
        raw = D / max(F, 1e-9)
        c = float(np.clip(raw, -CLIP, CLIP))
        s = np.sqrt(1.0 - c * c)
        J1 = (Jg - c * J0) / s
        de1_dc = -e0 / s + (g - c * e0) * c / s**3
        free = abs(raw) < CLIP and F > 1e-9
        if "field_ut" in self.index:
            J1[:, self.index["field_ut"]] = c / s + (de1_dc * (-D / F**2) if free else 0.0)
        if "field_down_ut" in self.index:
            J1[:, self.index["field_down_ut"]] = -1.0 / s + (de1_dc / F if free else 0.0)
        dRs = self._rotation_steps(x)
        for j, q in enumerate(_MIS):
            if q in self.index:
                J1[:, self.index[q]] = np.einsum("ij,ij->i", self.ahat @ dRs[j], u) / s
        J = np.empty((2 * n, p))
        J[0::2], J[1::2] = J0, J1
        return J
