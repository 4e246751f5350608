"""navlib.studies.gyro.bp_compare: the hot net against MATLAB's BP network (register entry C12)."""

import numpy as np
import pytest

from navlib import seeding, verdicts
from navlib.errors import InputError
from navlib.methods.bpnet import train_matlab_bp_many
from navlib.studies import gyro
from navlib.studies.gyro.bp_compare import _iqr_of_loo_rms

#: two sizes, few initialisations: the same code paths as the chapter's settings, a fraction of the time
SMALL = gyro.StudyParams(
    bp=gyro.BpSettings(n_hidden=3, sizes=(2, 3), n_inits=4, n_inits_converged=4)
)
rms = lambda v: float(np.sqrt(np.mean(np.square(v))))  # noqa: E731


@pytest.fixture(scope="module")
def loo():
    return gyro.bp_leave_one_out(SMALL)


def _t2():
    t = gyro.measured_tables().table2
    return t["latitude_error_deg"].to_numpy() * 60.0, t["drift_deg_h"].to_numpy()  # arcmin


def test_bp_settings_are_validated():
    assert gyro.StudyParams().bp.n_hidden == 10  # feedforwardnet's default hiddenSizes
    for kw, match in (
        (dict(n_inits=2), "n_bp_inits"),
        (dict(sizes=(2, 2)), "each size once"),
        (dict(sizes=()), "bp_sizes"),
        (dict(n_hidden=0), "bp_hidden"),
    ):
        with pytest.raises(InputError, match=match):
            gyro.BpSettings(**kw)
    with pytest.raises(InputError, match="bp"):
        gyro.StudyParams(bp=gyro.HotNetSettings())


def test_the_held_out_row_never_trains_and_seeds_are_children_per_fold_and_init(loo):
    x, y = _t2()
    n = len(y)
    folds = np.random.SeedSequence(SMALL.sim.seed).spawn(9)[8].spawn(n)  # the "bp_inits" experiment
    for i in (0, 7, n - 1):
        keep = np.arange(n) != i
        gens = [np.random.default_rng(seeding.child(folds[i], k)) for k in range(4)]
        nets = train_matlab_bp_many(x[keep], y[keep], 3, gens)
        ref = np.array([y[i] - net.predict(x[i : i + 1])[0] for net in nets])
        got = loo.matrix("every row trains", 3)[i]
        assert got == pytest.approx(ref, rel=1e-9, abs=1e-12)
        # a net that saw the held-out row predicts it differently
        leak = train_matlab_bp_many(
            x, y, 3, [np.random.default_rng(seeding.child(folds[i], k)) for k in range(4)]
        )
        assert got != pytest.approx(np.array([y[i] - net.predict(x[i : i + 1])[0] for net in leak]))
    # every reading and size has one error per row and initialisation; the RBF is the hot net's own LOO
    assert loo.matrix("every row trains", 2).shape == (n, 4)
    assert loo.matrix("dividerand validation stop", 3).shape == (n, 4)
    conv = loo.errors[loo.errors["reading"] == "trained to convergence"]
    assert (
        conv["epochs"].median()
        > 100
        > loo.errors.query("reading == 'every row trains'")["epochs"].median()
    )
    assert loo.rbf == pytest.approx(
        gyro.hot_leave_one_out(SMALL).rows["err our RBF"].to_numpy(), abs=0
    )


def test_bp_claims_by_hand(loo):
    cl = {c.key: c for c in gyro.bp_claims(SMALL)}
    assert set(cl) == {
        "gyro_rbf_vs_bp",
        "gyro_rbf_vs_bp_m2",
        "gyro_rbf_vs_bp_valstop",
        "gyro_rbf_vs_bp_converged",
        "gyro_rbf_vs_bp_spread",
    }
    seed = gyro.bootstrap_seed(SMALL.sim.seed, "rbf_vs_bp")
    e = loo.matrix("every row trains", 3)
    typical = np.median(np.abs(e), axis=1)  # a typical single training per row, not an ensemble
    c = cl["gyro_rbf_vs_bp"]
    assert c.reading == "BP 1-3-1, MATLAB defaults, every row trains"
    assert c.estimate.value == pytest.approx(rms(loo.rbf) - rms(typical))
    ref = verdicts.bootstrap([loo.rbf, typical], lambda a, b: rms(a) - rms(b), seed=seed)
    assert c.rule == "bootstrap over rows" and c.interval == pytest.approx(ref.interval)
    unpaired = verdicts.bootstrap(
        [loo.rbf, typical], lambda a, b: rms(a) - rms(b), seed=seed, paired=False
    )
    assert c.interval != pytest.approx(unpaired.interval)
    ensemble = np.median(e, axis=1)  # the median prediction's error: another statistic
    assert c.estimate.value != pytest.approx(rms(loo.rbf) - rms(ensemble))
    assert (c.boundary, c.holds_when, c.unit) == (0.0, "below", "deg/h")
    # the local-optimum row: 0 (newrb is deterministic) minus the BP's IQR over initialisations
    per_init = np.sqrt(np.mean(e**2, axis=0))
    q1, q3 = np.percentile(per_init, [25, 75])
    s = cl["gyro_rbf_vs_bp_spread"]
    assert s.estimate.value == pytest.approx(-(q3 - q1)) == pytest.approx(-_iqr_of_loo_rms(e))
    assert s.interval[1] <= 0.0 < q3 - q1
    # the RBF's side: two identical networks have no spread, and a constructed spread is found
    assert _iqr_of_loo_rms(np.ones((5, 4))) == 0.0
    assert _iqr_of_loo_rms(np.array([[1.0, 2.0, 3.0, 4.0]] * 3)) == pytest.approx(1.5)


def test_c12_folds_into_its_register_entry():
    from navlib import claims as reg

    primary = gyro.StudyParams(
        bp=gyro.BpSettings(n_hidden=10, sizes=(10,), n_inits=4, n_inits_converged=4)
    )
    cl = gyro.bp_claims(primary)
    rec = {r["id"]: r for r in reg.evaluate("gyro", [c.record() for c in cl])}["C12"]
    assert rec["status"] == "judged" and rec["key"] == "gyro_rbf_vs_bp"
    assert rec["verdict"] == {c.key: c for c in cl}["gyro_rbf_vs_bp"].verdict
