"""Tests for navlib.methods.compass_methods: the registry of paper A's and document B's compass methods
(ids, labels, readings, the DE families), the 8-position least squares and its position tolerance, and the
runs seeded by generators (moved here with the registry from tests/studies/compass/test_compass_study.py)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from navlib.angles import wrap_deg
from navlib.data.compass_sweeps import split_sweeps, unwrap_measured
from navlib.errors import InputError
from navlib.methods import compass_methods
from navlib.methods.compass_methods import (
    LEGACY_NAMES,
    METHODS,
    READINGS,
    RULE_READINGS,
    EightPosition,
    MethodParams,
    fit_family,
    fit_method,
    method_id,
)
from navlib.methods.de import DEParams
from navlib.methods.seeding import generators, sequence
from navlib.methods.smith import design, eight_position_indices, fit_smith, nearest_positions
from navlib.sensors.compass import PAPER_A_EARTH, simulate_train_test
from navlib.studies import compass


@pytest.fixture(scope="module")
def sw():
    train, _ = split_sweeps(simulate_train_test(earth=PAPER_A_EARTH, seed=2024))
    t = train["true_heading_deg"].to_numpy(float)
    return SimpleNamespace(
        t_train=t, x_train=unwrap_measured(t, train["measured_heading_deg"].to_numpy(float))
    )


def test_registry_ids_labels_and_readings():
    assert METHODS["elm"].stochastic and not METHODS["ls8"].stochastic
    labels = [m.label for m in METHODS.values()]
    assert len(set(labels)) == len(labels)  # one label per reading and trainer
    for ids in READINGS.values():
        assert all(i in METHODS for i in ids)
    for old, new in LEGACY_NAMES.items():
        assert method_id(old) == new
    with pytest.raises(InputError, match="unknown method"):
        method_id("BP (magic)")


def test_new_readings_are_registered_with_their_labels():
    labels = {m.label for m in METHODS.values()}
    for lab in (
        "ADE-BP full DE + trainlm",
        "ADE-BP full DE + trainlm, val. stop",
        "DE-BP full DE + trainlm",
        "ADE-BP F per individual",
        "ADE-BP F combined",
        "ADE-BP CR by rank",
        "LS 8-position (Smith, 5 terms)",
        "LS 8-position (planar, 5 par.)",
        "LS 8-position (harmonic, 3rd order)",
    ):
        assert lab in labels
    for reading, ade in RULE_READINGS.items():
        assert READINGS[reading][3] == ade and METHODS[ade].family[0][0] is True
        assert METHODS[ade].family[0][1:] != ("generation", "value")  # not the default rules


def test_third_order_ls_on_eight_readings_reproduces_a_third_order_error_exactly(sw):
    """A compass whose deviation is a known harmonic series to 3rd order in the measured heading: the
    3rd-order 8-position LS recovers it exactly (every test heading corrected to 1e-9 deg), Smith's 5 terms
    cannot (the 3rd harmonic aliases at 8 positions)."""
    coef = np.array([0.7, 3.0, -2.0, 1.1, 0.4, 1.2, -0.8])  # A, B1, C1, B2, C2, B3, C3 (deg)

    def deviation(m):
        return design(m, 3) @ coef

    true = np.arange(0.0, 363.0, 3.0)
    m = true.copy()
    for _ in range(200):  # measured: m - delta(m) = true
        m = true + deviation(m)
    assert np.max(np.abs(m - deviation(m) - true)) < 1e-10
    model = fit_smith(
        np.mod(m[eight_position_indices(true)], 360.0), true[eight_position_indices(true)], 3
    )
    np.testing.assert_allclose(model.coef, coef, atol=1e-9)
    h3 = fit_method("ls8_h3", m, true)[0]
    smith = fit_method("ls8", m, true)[0]
    assert np.max(np.abs(wrap_deg(h3.correct(m) - true))) < 1e-9
    assert np.max(np.abs(wrap_deg(smith.correct(m) - true))) > 0.5
    with pytest.raises(InputError, match="7 coefficients"):
        fit_smith(m[:6], true[:6], 3)


def _family_equals_alone(sw, mids, p, seeds):
    """fit_family(mids) gives each method's networks (and trainer info) as fit_method alone; the family."""
    fam = fit_family(mids, sw.x_train, sw.t_train, p, seeds=seeds)
    for mid in mids:
        for a, b in zip(fam[mid], fit_method(mid, sw.x_train, sw.t_train, p, seeds=seeds)):
            np.testing.assert_array_equal(a.net.theta, b.net.theta)
            for key in ("de_generations", "epochs", "stop"):
                assert a.info.get(key) == b.info.get(key)
    return fam


def test_family_of_one_de_stage_equals_each_method_alone(sw):
    """Pure DE and full DE + trainlm (with and without the validation stop) fitted from one shared DE stage
    give the same networks as each method fitted alone with the same seeds; so do reading 2's DE +
    trainlm with and without the validation stop from their own (shorter) stage."""
    p = MethodParams(de=DEParams(max_generations=30), lm=replace(MethodParams().lm, epochs=15))
    _family_equals_alone(sw, ("ade_bp_pure_f_ind", "ade_bp_full_trainlm_f_ind"), p, [3, 4])
    _family_equals_alone(
        sw, ("ade_bp_pure", "ade_bp_full_trainlm", "ade_bp_full_trainlm_val"), p, [1]
    )
    with pytest.raises(InputError, match="share one DE stage"):
        fit_family(("ade_bp_pure", "de_bp_full_trainlm"), sw.x_train, sw.t_train, p)
    with pytest.raises(InputError, match="share one DE stage"):
        fit_family(("de_bp_hybrid_trainlm", "de_bp_full_trainlm"), sw.x_train, sw.t_train, p)
    for hybrid_target, gens in (("normalised", 3000), ("deg2", 30)):
        ph = replace(p, hybrid_target=hybrid_target, de=DEParams(max_generations=gens))
        fam = _family_equals_alone(
            sw, ("de_bp_hybrid_trainlm", "de_bp_hybrid_trainlm_val"), ph, [0, 2]
        )
        if hybrid_target == "normalised":  # the stage stopped at the target
            assert all(0 < f.info["de_generations"] < 3000 for f in fam["de_bp_hybrid_trainlm"])


def test_the_chapter_reexports_the_registry():
    """The compass chapter's package imports the registry from the methods layer: the same objects, the
    methods' settings under the chapter's name StudyParams."""
    assert compass.METHODS is METHODS and compass.StudyParams is MethodParams
    assert compass.fit_method is fit_method and compass.EightPosition is EightPosition


def test_nearest_positions_within_a_tolerance():
    t = np.arange(5.0, 360.0, 10.0)  # 5, 15, ..., 355: 5 deg from 0, 90, 180, 270
    assert list(nearest_positions(t)) == [-1, 4, -1, 13, -1, 22, -1, 31]
    idx = nearest_positions(t, tol_deg=5.0)
    assert list(t[idx]) == [
        5.0,
        45.0,
        85.0,
        135.0,
        175.0,
        225.0,
        265.0,
        315.0,
    ]  # ties: the first reading
    assert list(nearest_positions(np.array([359.0, 44.0]), tol_deg=2.0)) == [
        0,
        1,
        -1,
        -1,
        -1,
        -1,
        -1,
        -1,
    ]
    assert list(nearest_positions(np.array([]), tol_deg=2.0)) == [-1] * 8
    with pytest.raises(InputError, match="no reading within 4 deg of true heading 0 deg"):
        eight_position_indices(t, tol_deg=4.0)
    with pytest.raises(InputError, match="tol_deg"):
        nearest_positions(t, tol_deg=-1.0)


def test_eight_position_ls_with_a_tolerance_uses_the_nearest_readings():
    """A Smith compass read every 10 deg from 5 deg: no reading at 0, 90, 180, 270, so the exact 8-position
    fit refuses; with 5 deg of tolerance it takes the nearest readings and recovers the deviation exactly."""
    coef = np.array([0.7, 3.0, -2.0, 1.1, 0.4])
    m = np.arange(5.0, 360.0, 10.0)
    t = m - design(m) @ coef
    with pytest.raises(InputError, match="no reading at true heading"):
        fit_method("ls8", m, t)
    p = MethodParams(ls_tol_deg=5.0)
    fitted = fit_method("ls8", m, t, p)[0]
    np.testing.assert_allclose(fitted.model.coef, coef, atol=1e-9)
    assert np.max(np.abs(wrap_deg(fitted.correct(m) - t))) < 1e-9
    for bad in (dict(ls_tol_deg=-1.0), dict(ls_tol_deg=30.0)):
        with pytest.raises(InputError, match="ls_tol_deg"):
            MethodParams(**bad)
    with pytest.raises(InputError, match="8-position model"):
        EightPosition("quadratic")


def test_fit_method_with_generators_equals_fit_method_with_seeds(sw):
    """Runs seeded by explicit generators: generator k of generators(seeds) gives run k's fit; a
    deterministic method fits once whatever it is given."""
    p = MethodParams(de=DEParams(max_generations=20), lm=replace(MethodParams().lm, epochs=10))
    for mid in ("elm", "bp_matlab", "ade_bp_full_trainlm"):
        a = fit_method(mid, sw.x_train, sw.t_train, p, seeds=[0, 2])
        b = fit_method(mid, sw.x_train, sw.t_train, p, rngs=generators([0, 2]))
        for fa, fb in zip(a, b):
            np.testing.assert_array_equal(fa.correct(sw.x_train), fb.correct(sw.x_train))
    c = fit_method(
        "elm", sw.x_train, sw.t_train, p, rngs=[np.random.default_rng(sequence(5, 1, 0))] * 1
    )
    assert not np.array_equal(c[0].correct(sw.x_train), a[0].correct(sw.x_train))
    assert len(fit_method("ls8", sw.x_train, sw.t_train, p, rngs=generators([0, 1, 2]))) == 1


def test_cost_units_group_the_methods_sharing_a_de_stage():
    p = MethodParams()
    units = compass_methods.fitting_units(
        p, ("ade_bp_pure", "elm", "ade_bp_full_trainlm", "de_bp_full_trainlm")
    )
    assert units == [("ade_bp_pure", "ade_bp_full_trainlm"), ("elm",), ("de_bp_full_trainlm",)]
    assert compass_methods.unit_cost(("elm",), p) == pytest.approx(0.001)
    cost = compass_methods.RUN_COST_S
    assert compass_methods.unit_cost(units[0], p) == pytest.approx(
        cost["de_stage"] + cost["trainlm"]
    )
    three = ("ade_bp_pure", "ade_bp_full_trainlm", "ade_bp_full_trainlm_val")
    assert compass_methods.unit_cost(three, p) == pytest.approx(
        cost["de_stage"] + 2 * cost["trainlm"]
    )
    half = replace(p, de=replace(p.de, max_generations=1500))
    assert compass_methods.unit_cost(three, half) == pytest.approx(
        compass_methods.unit_cost(three, p) / 2
    )
