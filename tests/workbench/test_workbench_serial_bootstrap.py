"""Issue 34: the parametric bootstrap of correlated noise, fast (navlib.workbench.diagnose): its tests from
inner products against the tests the diagnosis itself makes on whitened columns, and its re-estimates shared
by the diagnoses of one loop without changing a number."""

import numpy as np
import pytest

from navlib.workbench import bootstrap
from navlib.workbench import diagnose as dg
from navlib.workbench import ftests
from navlib.workbench import serial
from navlib.workbench.fit import fit_model
from navlib.workbench.magnetometer import simulate_hand_turned
from navlib.workbench.screen import screen


@pytest.fixture(scope="module")
def family_case():
    """A hand-turned magnetometer with soft iron hidden, fitted with hard iron; its screen's series (with
    gaps: rows set aside make segments), the candidates' fits."""
    data = simulate_hand_turned(
        {"hard_x_ut": 5.0, "soft_xy": 0.01},
        duration_s=30,
        noise_ut=0.3,
        noise_correlation=0.7,
        seed=3,
    )
    fit = fit_model("magnetometer", data, ["hard_iron"])
    ser = serial.series_of(data, fit.n, "magnetometer")
    ser = ser.without(np.random.default_rng(1).random(fit.n) < 0.02)
    fits = {e: fit.add(e) for e in ("soft_iron", "misalignment")}
    return fit, fits, ser


@pytest.mark.parametrize("kappa", [(), (0.6,), (0.7, -0.2), (0.5, 0.3, 0.2)])
def test_the_bootstrap_tests_from_inner_products_are_the_diagnosis_tests(family_case, kappa):
    """``_Family._min_p`` (Gram matrices of the columns, no whitened column) against the smallest p of the
    diagnosis's own tests under the same noise model: each candidate's GLS F test (``_gls_of``) and each
    structure shape's (``_shape_tests``), on whitened columns."""
    fit, fits, ser = family_case
    fam = bootstrap.Family(fit, fits, ser, 3)
    assert fam.gram
    nm = serial.NoiseModel(kappa, ser, fit.n)
    E = serial.colour(
        np.random.default_rng(2).standard_normal((len(ser.order), 3)), (0.6, 0.2), ser, fit.n
    )
    E[:, 2] += 0.05 * fits["soft_iron"].jacobian[:, -1]  # one vector with something to find
    # the bootstrap tests on the series' observations: the whitening drops the others, and without it (order
    # 0, which a replicate of correlated data never has) so does the reference here
    rows = ser.order if not kappa else np.arange(fit.n)
    J0 = fit.jacobian[rows]
    E[rows] -= (
        J0 @ np.linalg.lstsq(J0, E[rows], rcond=None)[0]
    )  # residuals of the model (as _gls_of takes)
    fast = fam._min_p(E[ser.order], nm)
    E = E[rows]
    shapes = [np.asarray(X0, float)[rows] for _, X0, _ in fit.spec.structure(fit)]
    for b in range(E.shape[1]):
        e0, Q0 = ftests.gls_of(E[:, b], J0, nm)
        ps = [p for _, p, _ in ftests.shape_tests(e0, Q0, shapes, nm, fit.n)]
        for f1 in fits.values():
            e1, Q1 = ftests.gls_of(E[:, b], f1.jacobian[rows], nm)
            e1 = e1 - Q1 @ (Q1.T @ e1)  # (the GLS residual already is)
            ps.append(
                ftests.f_test(
                    float(e0 @ e0), float(e1 @ e1), f1.n_params - fit.n_params, f1.n - f1.n_params
                )[0]
            )
        assert fast[b] == pytest.approx(min(ps), rel=1e-8, abs=1e-300)


def test_the_diagnoses_of_a_loop_share_the_bootstrap_and_its_numbers():
    """Two diagnoses on one screen use one memo of re-estimates; the levels are those of a diagnosis that
    re-estimates everything afresh (the memo cleared), to the last bit."""
    data = simulate_hand_turned(
        {"hard_x_ut": 5.0}, duration_s=30, noise_ut=0.3, noise_correlation=0.8, seed=6
    )
    fit = fit_model("magnetometer", data, [])
    sc = screen(fit)
    fit = sc.refit(fit)
    assert sc.noise.correlated
    first = dg.diagnose(fit, screen=sc)
    assert len(bootstrap.REESTIMATES) == 1
    memo = next(iter(bootstrap.REESTIMATES.values()))
    second = dg.diagnose(fit.add("hard_iron"), screen=sc)
    assert next(iter(bootstrap.REESTIMATES.values())) is memo
    bootstrap.REESTIMATES.clear()
    again = dg.diagnose(fit.add("hard_iron"), screen=sc)
    assert first.calibration.method == "parametric bootstrap"
    assert second.calibration == again.calibration


def test_all_replicates_at_once_equal_one_noise_model_at_a_time(family_case):
    """``_min_p_many`` (each column whitened with its own coefficients, the Gram blocks factored together)
    against ``_min_p`` column by column; ``whiten_each`` against ``whiten`` and ``whiten_transpose``."""
    fit, fits, ser = family_case
    fam = bootstrap.Family(fit, fits, ser, 3)
    kappas = [(0.5, 0.3, 0.2), (0.9, -0.4, 0.1), (0.1, 0.0, -0.3), (0.5, 0.3, 0.2)]
    models = [serial.NoiseModel(k, ser, fit.n) for k in kappas]
    E = serial.colour(
        np.random.default_rng(4).standard_normal((len(ser.order), 4)), (0.6, 0.2), ser, fit.n
    )
    E[:, 1] += 0.05 * fits["soft_iron"].jacobian[:, -1]
    Eo = E[ser.order]
    many = fam._min_p_many(Eo, models)
    one = [fam._min_p(Eo[:, [b]], nm)[0] for b, nm in enumerate(models)]
    assert np.allclose(many, one, rtol=1e-8, atol=0)
    assert np.array_equal(fam.minima(E, models), many)
    W = serial.whiten_each(Eo, kappas, ser)
    Wt = serial.whiten_each(Eo, kappas, ser, transpose=True)
    for b, k in enumerate(kappas):
        assert np.allclose(
            W[:, b], serial.whiten(Eo[:, b], k, ser, ordered=True), rtol=1e-13, atol=1e-13
        )
        assert np.allclose(
            Wt[:, b], serial.whiten_transpose(Eo[:, b], k, ser), rtol=1e-13, atol=1e-13
        )
