"""PaperDParams.from_notebook: the accelerometer notebook's flat papermill parameters become the chapter's
dataclasses in one call, exactly as the notebook's mapping cell builds them."""

import json
from dataclasses import replace
from pathlib import Path

import pytest

from navlib.errors import InputError
from navlib.methods.anfis import AnfisOptions
from navlib.methods.fish_swarm import FishSwarmParams
from navlib.sensors.accelerometer import AccelCoefficients, TumbleExperiment
from navlib.studies import accelerometer as D

NOTEBOOK = Path(__file__).resolve().parents[3] / "notebooks" / "accelerometer.ipynb"


def notebook_parameters() -> dict:
    """The values of the notebook's ``parameters`` cell (plain assignments), by name."""
    cells = json.loads(NOTEBOOK.read_text(encoding="utf-8"))["cells"]
    cell = next(c for c in cells if "parameters" in c.get("metadata", {}).get("tags", []))
    values = {}
    exec("".join(cell["source"]), {}, values)
    return values


def test_the_notebook_defaults_give_what_its_mapping_cell_builds():
    cell = notebook_parameters()
    assert set(cell) == set(D.NOTEBOOK_KEYS)  # every parameter is known, none is missing
    expected = D.PaperDParams(  # the notebook's mapping cell, written out
        coefficients=AccelCoefficients(bias_step_mg=0.12),
        experiment=TumbleExperiment(t_start_c=-40.0, t_stop_c=70.0, t_step_c=5.0, noise_ug=3.0),
        held_out_c=(-30.0, 5.0, 40.0),
        check_c=(-15.0, 20.0, 65.0),
        batch_spread_rel=0.25,
        fis_radius=0.5,
        anfis=AnfisOptions(epochs=40),
        swarm=FishSwarmParams(
            n_fish=8, generations=8, try_number=2, visual=0.3, step=0.15, delta=0.618, improved=True
        ),
        max_rules=40,
        seeds=(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11),
        grid_squash=(1.0, 1.25, 1.5, 2.0),
    )
    assert D.PaperDParams.from_notebook(**cell) == expected


@pytest.mark.parametrize(
    "name, value, field",
    [
        ("noise_ug", 5.0, lambda p: p.experiment.noise_ug),
        ("t_start_c", -35.0, lambda p: p.experiment.t_start_c),
        ("bias_step_mg", 0.0, lambda p: p.coefficients.bias_step_mg),
        ("crowd_delta", 0.5, lambda p: p.swarm.delta),
        ("improved", False, lambda p: p.swarm.improved),
        ("anfis_epochs", 7, lambda p: p.anfis.epochs),
        ("seeds", [3, 4], lambda p: p.seeds),
        ("fis_radius", 0.4, lambda p: p.fis_radius),
    ],
)
def test_one_parameter_changes_its_field_only(name, value, field):
    cell = notebook_parameters()
    base = D.PaperDParams.from_notebook(**cell)
    got = D.PaperDParams.from_notebook(**{**cell, name: value})
    assert field(got) == (tuple(value) if isinstance(value, list) else value)
    assert field(base) != field(got)
    # everything else is as before
    assert (
        replace(
            got,
            experiment=base.experiment,
            coefficients=base.coefficients,
            swarm=base.swarm,
            anfis=base.anfis,
            seeds=base.seeds,
            fis_radius=base.fis_radius,
        )
        == base
    )
    for part in ("experiment", "coefficients", "swarm", "anfis"):
        a, b = getattr(base, part), getattr(got, part)
        assert sum(getattr(a, f) != getattr(b, f) for f in a.__dataclass_fields__) <= 1


def test_absent_parameters_keep_the_defaults():
    assert D.PaperDParams.from_notebook() == D.PaperDParams()
    p = D.PaperDParams.from_notebook(noise_ug=1.0, unit_b_draws=10, n_workers=2, scheduler=None)
    assert p == replace(D.PaperDParams(), experiment=TumbleExperiment(noise_ug=1.0))


def test_an_unknown_parameter_raises_naming_it():
    with pytest.raises(InputError, match="'noise_mg'"):
        D.PaperDParams.from_notebook(**{**notebook_parameters(), "noise_mg": 3.0})


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(trial_ratios=(0.1, 0.0)), "trial_ratios"),
        (dict(trial_seeds=0), "trial_seeds"),
        (dict(noise_levels=()), "noise_levels"),
        (dict(batch_spreads=(0.1, 1.5)), "batch_spreads"),
        (dict(held_out_c=(-32.0,)), "not a set point"),
    ],
)
def test_the_other_parameters_are_checked_as_the_notebook_checks_them(kw, word):
    with pytest.raises(InputError, match=word):
        D.PaperDParams.from_notebook(**{**notebook_parameters(), **kw})
