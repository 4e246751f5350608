"""navlib.seeding is the one place seeds are made: the helpers that once built their own SeedSequences (ins's
``_part`` and its tests' spawn keys, the accelerometer's ``_sequence``, paper D's ``sim_seed``, paper E's
``seed_of``, the workbench bootstrap's stream, the torch seed of the MLP) now call it, and every one of them
still gives the stream it gave before: each is compared here with a SeedSequence built the old way."""

import numpy as np
import pytest

from navlib import seeding
from navlib.methods import seeding as methods_seeding
from navlib.sensors import accelerometer as acc
from navlib.sensors import ins
from navlib.studies import accelerometer as accel_study
from navlib.studies import celestial
from navlib.workbench import diagnose as dg

SS = np.random.SeedSequence


def same_stream(a: np.random.SeedSequence, b: np.random.SeedSequence) -> bool:
    return (
        np.array_equal(a.generate_state(8), b.generate_state(8))
        and np.random.default_rng(a).random(3).tolist()
        == np.random.default_rng(b).random(3).tolist()
    )


def test_methods_seeding_is_the_base_module():
    for name in ("sequence", "child", "as_int", "generators", "generator"):
        assert getattr(methods_seeding, name) is getattr(seeding, name)


def test_child_and_sequence_are_the_old_constructions():
    for seed in (0, 7, SS(7, spawn_key=(3, 1)), seeding.sequence(2024, 0, 5)):
        old = seed if isinstance(seed, SS) else SS(int(seed))  # ins._part, accel _sequence
        assert same_stream(seeding.child(seed), old)
        assert same_stream(
            seeding.child(seed, 1), SS(old.entropy, spawn_key=tuple(old.spawn_key) + (1,))
        )
    assert same_stream(seeding.sequence(5, 2, 0), SS(5, spawn_key=(2, 0)))
    assert not same_stream(
        seeding.child(7, 1), seeding.child(7, 2)
    )  # the check can tell streams apart
    assert seeding.as_int(SS(11)) == int(SS(11).generate_state(1)[0])


PROCEDURE = ins.Procedure(identify_h=1.0, navigate_h=2.0)


def _recorded_simulate(monkeypatch):
    seeds, real = [], ins.simulate

    def simulate(*args, seed=None, **kw):
        seeds.append(seed)
        return real(*args, seed=seed, **kw)

    monkeypatch.setattr(ins, "simulate", simulate)
    return seeds


@pytest.mark.parametrize("seed", [4, SS(9, spawn_key=(2, 3))])
def test_ins_navigation_draws_the_old_part_one(monkeypatch, seed):
    seeds = _recorded_simulate(monkeypatch)
    ins.run_procedure(
        None, procedure=PROCEDURE, seed=seed, imu=ins.ImuErrors(gyro_arw_deg_rt_h=0.001)
    )
    identify, after, before, unit = seeds
    assert identify is seed and unit is None
    old = seed if isinstance(seed, SS) else SS(int(seed))
    for nav in (after, before):
        assert same_stream(nav, SS(old.entropy, spawn_key=tuple(old.spawn_key) + (1,)))


def test_ins_simulated_tests_draw_the_old_spawn_keys(monkeypatch):
    drawn, procedure_seeds = [], []
    real_test = ins.random_test

    def random_test(rng, **kw):
        drawn.append(rng.bit_generator.state)
        return real_test(rng, **kw)

    def run_procedure(identify, *, seed, **kw):
        procedure_seeds.append(seed)

    monkeypatch.setattr(ins, "random_test", random_test)
    monkeypatch.setattr(ins, "run_procedure", run_procedure)
    ins.simulated_tests([0.01, 0.02, 0.03], seed=6)
    for i in range(3):
        assert drawn[i] == np.random.default_rng(SS(6, spawn_key=(i, 0))).bit_generator.state
        assert same_stream(procedure_seeds[i], SS(6, spawn_key=(i, 1)))


@pytest.mark.parametrize("seed", [3, SS(1000, spawn_key=(2, 1))])
def test_accelerometer_noise_is_the_old_stream(seed):
    exp, coef = acc.TumbleExperiment(), acc.AccelCoefficients()
    old = seed if isinstance(seed, SS) else SS(seed)
    df = acc.simulate_tumble(coef, exp, seed)
    z = np.random.default_rng(old).standard_normal(len(df))
    np.testing.assert_allclose(
        df.output_mg - df.true_output_mg, 1e-3 * exp.noise_ug * z, rtol=0, atol=1e-12
    )
    bt = acc.bias_test(coef, exp, seed)
    z = np.random.default_rng(old).standard_normal((len(bt), 2)).mean(axis=1)
    np.testing.assert_allclose(
        bt.bias_mg - bt.true_bias_mg, 1e-3 * exp.noise_ug * z, rtol=0, atol=1e-12
    )


def test_paper_d_and_e_seeds_are_the_old_ones():
    for s in range(4):
        for part, k in accel_study.SIM_PARTS.items():
            assert same_stream(
                accel_study.sim_seed(s, part), SS(accel_study.SIM_ENTROPY, spawn_key=(s, k))
            )
    spec = celestial.StudySpec()
    for rep in range(3):
        for part, key in (
            ("noise", (1, 4)),
            ("manoeuvre", (2,)),
            ("network", ()),
            ("timing", (0,)),
        ):
            old = SS(int(spec.seed), spawn_key=(rep, celestial.SEED_PARTS[part]) + key)
            assert celestial.seed_of(spec, rep, part, *key) == int(old.generate_state(1)[0])


def test_the_workbench_bootstrap_stream_is_the_old_one():
    for seed in (0, 5):
        assert same_stream(
            seeding.child(seed, dg._BOOTSTRAP_KEY), SS(seed, spawn_key=(dg._BOOTSTRAP_KEY,))
        )


def test_the_torch_initial_weights_are_the_old_ones():
    torch = pytest.importorskip("torch")
    from navlib.methods import mlp

    p = mlp.MLPParams(init="torch", n_in=3, n_hidden=4)
    w = mlp._initial_weights(p, 11)
    torch.manual_seed(int(SS(11).generate_state(1)[0]))
    l1 = torch.nn.Linear(3, 4, dtype=torch.float64)
    np.testing.assert_array_equal(w["W1"], l1.weight.detach().numpy())
