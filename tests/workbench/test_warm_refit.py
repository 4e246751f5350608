"""Issue 34, calibrate's speed: the screen's outlier rounds, its richest model and the refit on the rows
kept start from the previous optimum (the system's ``refit`` hook: Gauss-Newton steps with the analytic
Jacobian) instead of full fits from several starts.  The fast path must land where the full fits land."""

import numpy as np
import pandas as pd
import pytest

import navlib.workbench.screen as screen_module
from navlib.workbench.calibration import calibrate
from navlib.workbench.effects import Effect
from navlib.workbench.fit import fit_model, refit_rows
from navlib.workbench.free_kernel import FreeKernel
from navlib.workbench.local_field import parameter_covariance
from navlib.workbench.free_simulation import simulate_free
from navlib.workbench.magnetometer_free import (
    DERIVED,
    SYSTEM,
    gauss_newton,
    warm_refit,
    with_invariants,
)

TRUTH = {
    "hard_x_ut": 12.0,
    "hard_y_ut": -5.0,
    "hard_z_ut": 3.0,
    "scale_x": 0.02,
    "soft_xy": 0.01,
    "mis_z_deg": 1.0,
    "temp_x_ut_c": 0.1,
}
SPIKES = {100: ("mag_x_ut", 25.0), 333: ("mag_y_ut", -30.0), 650: ("mag_z_ut", 40.0)}


def _spiked(seed: int) -> pd.DataFrame:
    """1,000 rows of a hand-turned sensor with three isolated spikes planted."""
    d = simulate_free(TRUTH, duration_s=100.0, seed=seed).copy()
    for row, (col, jump) in SPIKES.items():
        d.loc[d.index[row], col] += jump
    return with_invariants(d.drop(columns=list(DERIVED)))  # the derived columns of the spiked field


def _full(fit, data, effects=None):
    """The path before the hook: a full fit from the previous parameters and the linearised start."""
    effects = fit.effects if effects is None else effects
    return fit_model(fit.spec, data, effects, start=fit.params, user_effects=fit.user_effects)


def _in_std(a, b) -> float:
    """Largest parameter difference of two fits in units of ``a``'s standard errors."""
    names, cov = parameter_covariance(a)
    sd = np.sqrt(np.diag(cov))
    return max(abs(a.params[q] - b.params[q]) / s for q, s in zip(names, sd))


@pytest.mark.parametrize("seed", [1, 2])
@pytest.mark.parametrize(
    "model",
    [
        ("hard_iron", "scale", "soft_iron"),
        ("hard_iron", "scale", "soft_iron", "misalignment", "temperature"),
    ],
)
def test_warm_refit_lands_where_the_full_fit_does(seed, model):
    """Without the planted rows, from the fit on all rows: the same minimum as the full fit from several
    starts (well within 0.01 standard errors), the same residuals, Jacobian and temperature centre."""
    d = _spiked(seed)
    fit = fit_model(SYSTEM, d, list(model))
    kept = d.drop(index=d.index[list(SPIKES)])
    warm = refit_rows(fit, kept)
    full = _full(fit, kept)
    assert warm.effects == full.effects and list(warm.params) == list(full.params)
    assert _in_std(full, warm) < 0.01
    assert fit.rss > warm.rss  # the spikes are gone: it did move
    assert warm.rss <= full.rss * (1 + 1e-9)  # at least as far down as scipy went
    np.testing.assert_allclose(warm.residuals, full.residuals, atol=1e-3)
    np.testing.assert_allclose(
        warm.jacobian, full.jacobian, atol=1e-5 * np.abs(full.jacobian).max()
    )
    assert warm.model == full.model  # the temperature centre of the rows kept
    assert warm.available == fit.available
    new = warm.predict(kept)  # the fit predicts like a full fit's
    np.testing.assert_allclose(new, full.predict(kept), atol=1e-3)


def test_warm_refit_with_more_effects_is_the_richer_full_fit():
    """The screen's richest model from the calibration model's optimum (the new parameters at zero)."""
    d = _spiked(3)
    fit = fit_model(SYSTEM, d, ["hard_iron", "scale", "soft_iron"])
    rich = ("hard_iron", "scale", "soft_iron", "misalignment", "temperature")
    warm = refit_rows(fit, d, rich)
    full = _full(fit, d, rich)
    assert warm.effects == rich and list(warm.params) == list(full.params)
    assert _in_std(full, warm) < 0.01


def test_calibrate_fast_path_equals_the_full_refits(monkeypatch):
    """calibrate on 1,000 rows with planted spikes: the outliers set aside, the noise model and every
    parameter and standard error as with the full refits from several starts the screen made before."""
    d = _spiked(4)
    planted = sorted(r + 1 for r in SPIKES)  # 1-based rows
    fit = fit_model(SYSTEM, d, ["hard_iron", "scale", "soft_iron"])
    sc_fast = screen_module.screen(fit)
    fast = calibrate(d)
    monkeypatch.setattr(screen_module, "refit_rows", _full)
    sc_slow = screen_module.screen(fit)
    slow = calibrate(d)
    assert sc_fast.rows_set_aside == sc_slow.rows_set_aside == planted
    assert sc_fast.rich.effects == sc_slow.rich.effects
    assert _in_std(sc_slow.rich, sc_fast.rich) < 0.01
    assert sc_fast.noise.kappa == pytest.approx(sc_slow.noise.kappa, abs=1e-3)
    assert fast["outliers_set_aside"] == slow["outliers_set_aside"] >= len(SPIKES)
    assert fast["noise"] == slow["noise"]
    assert fast["warnings"] == slow["warnings"]
    for e, params in slow["effects"].items():
        for q, v in params.items():
            w = fast["effects"][e][q]
            assert abs(w["value"] - v["value"]) < 0.01 * v["std"], q
            assert w["std"] == pytest.approx(v["std"], rel=1e-3), q


def test_no_fast_path_for_user_effects_or_without_convergence():
    """A model with a user effect is fitted in full (the hook declines); Gauss-Newton that cannot converge
    in the steps allowed says so (None) instead of returning a point short of the minimum."""
    d = _spiked(1)
    bump = Effect(
        "bump",
        ("bump_ut",),
        ("uT",),
        "a constant on the magnitude",
        contribution=lambda p, data: np.column_stack(
            [np.full(len(data), p["bump_ut"]), np.zeros(len(data))]
        ),
    )
    fit = fit_model(SYSTEM, d, ["hard_iron", "bump"], user_effects=(bump,))
    assert warm_refit(fit, d) is None
    again = refit_rows(fit, d.iloc[10:])  # falls back to the full fit
    assert again.effects == fit.effects and "bump_ut" in again.params
    fit = fit_model(SYSTEM, d, ["hard_iron", "scale", "soft_iron"])
    names = list(fit.params)
    kern = FreeKernel(
        names,
        d[["mag_x_ut", "mag_y_ut", "mag_z_ut"]].to_numpy(float),
        d[["acc_x_ms2", "acc_y_ms2", "acc_z_ms2"]].to_numpy(float),
    )
    far = np.array([fit.params[q] for q in names]) + 5.0  # far from the minimum
    assert gauss_newton(kern, far, steps=1) is None
    x, J = gauss_newton(kern, far)
    assert np.allclose(x, [fit.params[q] for q in names], atol=1e-3)
    assert J.shape == (2 * len(d), len(names))


def test_extrapolated_steps_reach_the_same_minimum_in_fewer_steps(monkeypatch):
    """A sensor in motion (the accelerometer sees 3 m/s^2 besides gravity): Gauss-Newton converges
    linearly; the extrapolated step (Aitken) reaches the same minimum in fewer Jacobians."""
    import navlib.workbench.magnetometer_free as mf

    d = simulate_free(TRUTH, duration_s=100.0, acc_noise_ms2=3.0, seed=5)
    fit = fit_model(SYSTEM, d, ["hard_iron", "scale", "soft_iron"])
    names = list(fit.params) + ["mis_x_deg", "mis_y_deg", "mis_z_deg"]
    kern = mf.kernel_of(d, names)
    x0 = np.array([fit.params.get(q, 0.0) for q in names])
    calls = []
    jac = FreeKernel.jacobian
    monkeypatch.setattr(FreeKernel, "jacobian", lambda self, x: calls.append(1) or jac(self, x))
    fast = gauss_newton(kern, x0, steps=200)
    n_fast = len(calls)
    monkeypatch.setattr(mf, "ACCEL_RHO", 0.0)  # never extrapolate
    calls.clear()
    plain = gauss_newton(kern, x0, steps=200)
    assert fast is not None and plain is not None
    assert n_fast < len(calls), (n_fast, len(calls))
    full = fit_model(
        SYSTEM, d, ["hard_iron", "scale", "soft_iron", "misalignment"], start=fit.params
    )
    names_cov, cov = parameter_covariance(full)
    sd = dict(zip(names_cov, np.sqrt(np.diag(cov))))
    for x, _ in (fast, plain):
        assert max(abs(v - full.params[q]) / sd[q] for q, v in zip(names, x)) < 0.01


@pytest.mark.parametrize("seed", [1, 6])
def test_a_single_start_fit_by_gauss_newton_is_scipys(monkeypatch, seed):
    """A fit from the linearised start alone (no previous parameters) takes Gauss-Newton steps; scipy's
    trust region from the same start (what it did before, and still does when the steps do not converge)
    ends at the same minimum."""
    import navlib.workbench.magnetometer_free as mf

    d = _spiked(seed)
    model = ["hard_iron", "scale", "soft_iron", "misalignment"]
    gn = fit_model(SYSTEM, d, model)
    monkeypatch.setattr(mf, "gauss_newton", lambda kern, x0, steps=0: None)
    ref = fit_model(SYSTEM, d, model)
    assert list(gn.params) == list(ref.params)
    assert _in_std(ref, gn) < 0.01 and gn.rss <= ref.rss * (1 + 1e-9)
    np.testing.assert_allclose(gn.residuals, ref.residuals, atol=1e-3)


def test_leverage_by_cholesky_is_the_gram_schmidt_basis():
    """The screen's leverages from the Cholesky factor of the scaled Gram matrix are the row sums of
    squares of the Gram-Schmidt basis, also with columns of very different scales; with a dependent column
    (dropped by Gram-Schmidt) the basis is used."""
    from navlib.workbench.linalg import leverage, orth_basis

    rng = np.random.default_rng(0)
    X = rng.normal(size=(500, 12)) * 10.0 ** rng.integers(-3, 3, 12)
    for Y in (X, np.column_stack([X, X[:, 1] * 2 - X[:, 3]]), X[:, :0]):
        q = orth_basis(Y) if Y.shape[1] else np.zeros((len(Y), 0))
        h = leverage(Y)
        assert h.shape == (len(Y),)
        np.testing.assert_allclose(h, np.sum(q**2, axis=1), rtol=0, atol=1e-12)
    assert leverage(X).sum() == pytest.approx(12.0)
