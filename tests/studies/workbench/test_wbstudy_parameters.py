"""The workbench notebook's parameters as one dataclass (navlib.studies.workbench.parameters.WorkbenchParams):
its papermill cell's defaults give what the notebook's checking cell builds, one changed parameter changes
its field, and what the notebook would refuse is refused."""

import json
from dataclasses import replace

import pytest

from navlib.errors import InputError
from navlib.paths import ROOT
from navlib.studies import workbench as wb
from navlib.workbench.effects import check_effects

NOTEBOOK = ROOT / "notebooks" / "workbench.ipynb"


def notebook_defaults() -> dict:
    """The notebook's parameters cell (tagged ``parameters``), run: name -> default."""
    cells = json.loads(NOTEBOOK.read_text(encoding="utf-8"))["cells"]
    cell = next(c for c in cells if "parameters" in c.get("metadata", {}).get("tags", []))
    names: dict = {}
    exec("".join(cell["source"]), {}, names)
    return names


def test_the_notebooks_defaults_give_what_its_cells_build():
    cell = notebook_defaults()
    params = wb.WorkbenchParams.from_notebook(**cell)
    # what the notebook's cells build from the defaults, written out
    expected = wb.WorkbenchParams(
        hidden_effect="temperature",
        hidden_ratio=10.0,
        noise_deg=0.1,
        start_model="misalignment,hard_iron",
        sim_seed=7,
        alpha=0.025,
        three_cycle_deg=0.5,
        study_seeds=20,
        study_null_trials=150,
        drift_null_trials=300,
        ooc_seeds=9,
        mag_row_step=3,
        corr_seeds=10,
        n_workers=2,
        scheduler=None,
    )
    assert params == expected == wb.WorkbenchParams()
    assert (
        params.start
        == check_effects("compass", "misalignment,hard_iron".split(","))
        == ("misalignment", "hard_iron")
    )
    assert {k: getattr(params, k) for k in cell} == cell  # every parameter of the cell, as given


def test_one_changed_parameter_changes_its_field():
    base = wb.WorkbenchParams.from_notebook(**notebook_defaults())
    p = wb.WorkbenchParams.from_notebook(**{**notebook_defaults(), "mag_row_step": 6})
    assert p.mag_row_step == 6 and p == replace(base, mag_row_step=6)
    p = wb.WorkbenchParams.from_notebook(start_model="hard_iron,misalignment,soft_iron")
    assert (
        p.start == ("misalignment", "hard_iron", "soft_iron")
        and p.hidden_effect == base.hidden_effect
    )
    p = wb.WorkbenchParams.from_notebook(scheduler="tcp://127.0.0.1:8786")
    assert p.scheduler == "tcp://127.0.0.1:8786" and replace(p, scheduler=None) == base


def test_an_unknown_or_bad_parameter_is_refused_by_name():
    with pytest.raises(InputError, match="'mag_rowstep'"):
        wb.WorkbenchParams.from_notebook(mag_rowstep=3)
    with pytest.raises(InputError, match="'start'"):  # built, not given
        wb.WorkbenchParams.from_notebook(start=("bias",))
    with pytest.raises(InputError, match="alpha"):
        wb.WorkbenchParams.from_notebook(alpha=1.5)
    with pytest.raises(InputError, match="n_workers"):
        wb.WorkbenchParams.from_notebook(n_workers=0)
    with pytest.raises(InputError, match="already in start_model"):
        wb.WorkbenchParams.from_notebook(hidden_effect="hard_iron")
    with pytest.raises(InputError):
        wb.WorkbenchParams.from_notebook(hidden_effect="no_such_effect")
