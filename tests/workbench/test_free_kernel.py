"""The reference-free invariants' analytic Jacobian against finite differences, and the kernel against
the frame-based residuals it replaced (issue 34)."""

import numpy as np
import pytest
from scipy.optimize._numdiff import approx_derivative
from scipy.spatial.transform import Rotation

from navlib.workbench.free_kernel import FreeKernel, rotation_deg

ALL = [
    "field_ut",
    "field_down_ut",
    "hard_x_ut",
    "hard_y_ut",
    "hard_z_ut",
    "scale_x",
    "scale_y",
    "soft_xy",
    "soft_xz",
    "soft_yz",
    "temp_x_ut_c",
    "temp_y_ut_c",
    "temp_z_ut_c",
    "mis_x_deg",
    "mis_y_deg",
    "mis_z_deg",
]
X = dict(
    zip(ALL, [45, 30, 3, -2, 1, 0.02, -0.01, 0.01, 0.005, -0.007, 0.1, -0.05, 0.02, 1.0, -0.5, 0.3])
)


def _data(seed=1, n=60):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)) * 40, rng.normal(size=(n, 3)) * 9.8, rng.normal(size=n) * 5


@pytest.mark.parametrize("acc", [True, False])
@pytest.mark.parametrize(
    "names",
    [
        ALL,
        ["field_ut", "field_down_ut", "hard_x_ut", "hard_y_ut", "hard_z_ut"],
        ["field_ut", "field_down_ut", "scale_x", "mis_z_deg"],
    ],
)
def test_jacobian_matches_finite_differences(acc, names):
    names = [q for q in names if acc or (q != "field_down_ut" and not q.startswith("mis"))]
    m, a, dt = _data()
    k = FreeKernel(names, m, a if acc else None, dt)
    x = np.array([X[q] for q in names], float)
    J = k.jacobian(x)
    Jn = approx_derivative(lambda z: k.residuals(z).ravel(), x, method="3-point")
    assert J.shape == Jn.shape == (len(m) * (2 if acc else 1), len(names))
    assert np.abs(J - Jn).max() < 1e-6 * np.abs(Jn).max()


def test_clipped_dip_ratio_has_no_field_term():
    """Where D/F is clipped at 0.99 the ratio no longer moves with F or D."""
    m, a, dt = _data(2)
    names = ["field_ut", "field_down_ut", "hard_x_ut"]
    k = FreeKernel(names, m, a, dt)
    x = np.array([10.0, 50.0, 1.0])
    Jn = approx_derivative(lambda z: k.residuals(z).ravel(), x, method="3-point")
    assert np.abs(k.jacobian(x) - Jn).max() < 1e-6 * np.abs(Jn).max()


def test_residuals_follow_the_definition():
    """e0 = |M (m - b - k dT)| - F and e1 = (g - c e0)/sqrt(1 - c^2), written out without the kernel."""
    m, a, dt = _data(3)
    p = X
    K = np.array(
        [
            [p["scale_x"], p["soft_xy"], p["soft_xz"]],
            [p["soft_xy"], p["scale_y"], p["soft_yz"]],
            [p["soft_xz"], p["soft_yz"], -p["scale_x"] - p["scale_y"]],
        ]
    )
    b = np.array([p["hard_x_ut"], p["hard_y_ut"], p["hard_z_ut"]])
    kt = np.array([p["temp_x_ut_c"], p["temp_y_ut_c"], p["temp_z_ut_c"]])
    u = (m - b - dt[:, None] * kt) @ (np.eye(3) + K).T
    e0 = np.linalg.norm(u, axis=1) - p["field_ut"]
    R = Rotation.from_rotvec(
        np.radians([p["mis_x_deg"], p["mis_y_deg"], p["mis_z_deg"]])
    ).as_matrix()
    g = (
        np.sum(a / np.linalg.norm(a, axis=1, keepdims=True) * (u @ R.T), axis=1)
        - p["field_down_ut"]
    )
    c = p["field_down_ut"] / p["field_ut"]
    want = np.column_stack([e0, (g - c * e0) / np.sqrt(1 - c * c)])
    got = FreeKernel(ALL, m, a, dt).residuals(np.array([p[q] for q in ALL], float))
    assert np.allclose(got, want, rtol=1e-12, atol=1e-10)


@pytest.mark.parametrize(
    "v", [[0, 0, 0], [1, -0.5, 0.3], [170, 20, -40], [1e-9, 0, 0], [0, 0, -180]]
)
def test_rotation_deg_is_scipys(v):
    assert np.allclose(rotation_deg(v), Rotation.from_rotvec(np.radians(v)).as_matrix(), atol=1e-14)


@pytest.mark.parametrize("acc", [True, False])
@pytest.mark.parametrize("temp", [True, False])
@pytest.mark.parametrize(
    "names",
    [
        ALL,
        ["field_ut", "field_down_ut", "hard_x_ut", "hard_y_ut", "hard_z_ut", "soft_xz"],
        ["field_ut", "field_down_ut", "scale_x", "mis_z_deg", "temp_y_ut_c", "my_user_q"],
    ],
)
def test_compiled_loop_equals_the_numpy_reference(acc, temp, names):
    """The compiled residuals and Jacobian (numba) are the numpy formulation's, to rounding; a parameter the
    kernel does not know (a user effect's) has a zero column."""
    names = [q for q in names if acc or (q != "field_down_ut" and not q.startswith("mis"))]
    m, a, dt = _data(seed=3, n=200)
    k = FreeKernel(names, m, a if acc else None, dt if temp else None)
    x = np.array([X.get(q, 0.7) for q in names], float)
    r, rr = k.residuals(x), k.reference_residuals(x)
    assert r.shape == rr.shape
    np.testing.assert_allclose(r, rr, rtol=1e-12, atol=1e-11)
    J, Jr = k.jacobian(x), k.reference_jacobian(x)
    assert J.shape == Jr.shape
    np.testing.assert_allclose(J, Jr, rtol=1e-12, atol=1e-12 * np.abs(Jr).max())
    if "my_user_q" in names:
        assert not J[:, names.index("my_user_q")].any()
