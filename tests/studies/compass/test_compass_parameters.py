"""navlib.studies.compass.parameters.params_from_notebook: the compass notebook's flat papermill parameters
turned into the chapter's objects in one call, as the notebook's own mapping cell built them."""

import json
from dataclasses import replace

import pytest

from navlib.errors import InputError
from navlib.methods.bpnet import AdamParams
from navlib.methods.de import DEParams
from navlib.methods.lm import LMParams
from navlib.paths import ROOT
from navlib.sensors.compass import CompassErrors
from navlib.studies import compass
from navlib.studies.compass import CompassDrawRule, StudyParams, params_from_notebook

NOTEBOOK = ROOT / "notebooks" / "compass.ipynb"


def _notebook_cell() -> dict:
    """The notebook's ``parameters`` cell, run: its names and default values."""
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    cell = next(c for c in nb["cells"] if "parameters" in c.get("metadata", {}).get("tags", []))
    values: dict = {}
    exec("".join(cell["source"]), {}, values)
    return values


@pytest.fixture(scope="module")
def cell():
    if not NOTEBOOK.is_file():
        pytest.skip("notebooks/compass.ipynb is not in this checkout")
    return _notebook_cell()


def test_the_defaults_are_the_notebooks_parameters_cell(cell):
    assert compass.NOTEBOOK_DEFAULTS == cell


def test_the_notebooks_defaults_build_what_its_mapping_cell_builds(cell):
    got = params_from_notebook(**cell)
    # the notebook's mapping cell, written out with its default values
    errors = replace(CompassErrors().scaled(1.0), noise_ut=0.04)
    params = StudyParams(
        n_hidden=6,
        de=DEParams(
            pop_size=95,
            max_generations=3000,
            target_fitness=0.2,
            f=0.5,
            cr=0.6,
            f_min=0.3,
            f_max=0.9,
            cr_min=0.1,
            cr_max=0.9,
            bound=10.0,
        ),
        pure_target="deg2",
        hybrid_target="normalised",
        lm=LMParams(epochs=1000, max_fail=6),
        adam=AdamParams(epochs=3000, lr=0.01),
        elm_nodes=19,
        elm_range=5.0,
        elm_max_nodes=30,
        elm_goal_deg=0.1,
        elm_max_iter=200,
    )
    draw_rule = CompassDrawRule(n_compasses=5, tolerance_deg=2.0, seed=7)
    assert got == (errors, params, draw_rule)
    assert got.errors == errors and got.params == params and got.draw_rule == draw_rule
    assert params_from_notebook() == got  # a key left out takes the notebook's default


@pytest.mark.parametrize(
    "key, value, field",
    [
        ("noise_ut", 0.02, lambda r: r.errors.noise_ut),
        ("error_scale", 0.5, lambda r: r.errors.hard_iron_ut),
        ("n_hidden", 8, lambda r: r.params.n_hidden),
        ("pop_size", 40, lambda r: r.params.de.pop_size),
        ("ade_cr_max", 0.8, lambda r: r.params.de.cr_max),
        ("weight_bound", 5.0, lambda r: r.params.de.bound),
        ("hybrid_target", "deg2", lambda r: r.params.hybrid_target),
        ("lm_max_fail", 3, lambda r: r.params.lm.max_fail),
        ("bp_lr", 0.001, lambda r: r.params.adam.lr),
        ("elm_goal_deg", 0.2, lambda r: r.params.elm_goal_deg),
        ("robust_seed", 11, lambda r: r.draw_rule.seed),
        ("robust_tolerance_deg", 3.0, lambda r: r.draw_rule.tolerance_deg),
    ],
)
def test_one_parameter_changes_its_field_only(key, value, field):
    base, changed = params_from_notebook(), params_from_notebook(**{key: value})
    assert field(changed) != field(base)
    if key == "error_scale":
        assert changed.errors == replace(CompassErrors().scaled(0.5), noise_ut=0.04)
    else:
        assert field(changed) == value
    assert sum(a != b for a, b in zip(base, changed)) == 1  # one of errors, params, draw_rule moved


def test_parameters_the_mapping_does_not_use_are_taken_and_checked():
    assert (
        params_from_notebook(n_seeds=6, n_box_seeds=6, small_sizes=[6, 121])
        == params_from_notebook()
    )
    for bad, name in (
        (dict(n_seeds=1), "n_seeds"),
        (dict(n_box_seeds=21), "n_box_seeds"),
        (dict(real_ls_tolerance_deg=30.0), "real_ls_tolerance_deg"),
        (dict(small_sizes=[5]), "small_sizes"),
        (dict(error_scale=-1.0), "error_scale"),
    ):
        with pytest.raises(InputError, match=name):
            params_from_notebook(**bad)


def test_an_unknown_key_names_itself():
    with pytest.raises(InputError, match="'n_seed'"):
        params_from_notebook(n_seed=20)
