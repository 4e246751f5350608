"""navlib.seeding is the one place seeds are made.  The inertial simulator is held to behaviours (a run is a
function of its seed; its two navigations share one noise stream; each simulated test draws a stream of its
own); the helpers that once built their own SeedSequences (the accelerometer's ``_sequence``, paper D's
``sim_seed``, paper E's ``seed_of``, the workbench bootstrap's stream, the torch seed of the MLP) still give
the stream they gave before: each is compared here with a SeedSequence built the old way."""

import numpy as np
import pytest

from navlib import seeding
from navlib.methods import seeding as methods_seeding
from navlib.sensors import accelerometer as acc
from navlib.sensors import ins
from navlib.studies import accelerometer as accel_study
from navlib.studies import celestial
from navlib.workbench import bootstrap

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


IMU = ins.ImuErrors(gyro_arw_deg_rt_h=0.001)


def _track(r: ins.ProcedureResult) -> np.ndarray:
    return np.concatenate(
        [r.identify_run.north_m, r.after.north_m, r.after.east_m, r.before.north_m]
    )


@pytest.mark.parametrize("seed", [4, 9])
def test_ins_procedure_is_a_function_of_its_seed(seed):
    """An int seed and its SeedSequence give the same run; another seed another run."""
    run = lambda s: _track(ins.run_procedure(None, procedure=PROCEDURE, seed=s, imu=IMU))  # noqa: E731
    assert np.array_equal(run(seed), run(SS(seed)))
    assert not np.array_equal(run(seed), run(seed + 1))


def test_ins_navigations_with_and_without_compensation_share_their_noise():
    """The two navigations after identification draw one stream: they differ by the identified drift's
    deterministic response alone (the errors are affine in the axial drift)."""
    r = ins.run_procedure(None, procedure=PROCEDURE, seed=4, imu=IMU)
    np.testing.assert_allclose(
        r.after.north_m,
        r.before.north_m - r.identified_drift_deg_h * r.unit_response.north_m,
        rtol=1e-9,
        atol=1e-6,
    )
    assert r.identified_drift_deg_h != 0


def test_ins_simulated_tests_each_draw_a_stream_of_their_own():
    """Test i draws from child i of the seed: dropping or changing another test leaves it as it was."""
    three = ins.simulated_tests([0.01, 0.02, 0.03], seed=6, procedure=PROCEDURE)
    two = ins.simulated_tests([0.01, 0.02], seed=6, procedure=PROCEDURE)
    other = ins.simulated_tests([0.05, 0.02], seed=6, procedure=PROCEDURE)
    for a, b in zip(two, three):
        assert np.array_equal(_track(a), _track(b))
    assert np.array_equal(_track(other[1]), _track(two[1]))
    assert not np.array_equal(_track(other[0]), _track(two[0]))


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
            seeding.child(seed, bootstrap.BOOTSTRAP_KEY),
            SS(seed, spawn_key=(bootstrap.BOOTSTRAP_KEY,)),
        )


def test_the_torch_initial_weights_are_the_old_ones():
    torch = pytest.importorskip("torch")
    from navlib.methods import mlp

    p = mlp.MLPParams(init="torch", n_in=3, n_hidden=4)
    w = mlp._initial_weights(p, 11)
    torch.manual_seed(int(SS(11).generate_state(1)[0]))
    l1 = torch.nn.Linear(3, 4, dtype=torch.float64)
    np.testing.assert_array_equal(w["W1"], l1.weight.detach().numpy())
