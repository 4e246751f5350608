"""``grid`` reads each value as the type of the notebook's default (issue 35, item 7), also where the
parameters cell casts it (``n = int(2)``) or annotates it (``n: int = ...``), and refuses, in one line naming
the parameter, what does not convert."""

import pandas as pd
import pytest

from navbook import cli, grid
from navlib.errors import InputError
from test_robust_outputs import tiny_notebook

CELL = """n = int(2)
x = float("1e-3")
flag = bool(0)
label = str(5)
m: float = 2
k: int = len([1, 2])
q: float = np.sqrt(2)
expr = np.pi
plain = 3
"""


@pytest.fixture(scope="module")
def params(tmp_path_factory):
    return grid.notebook_parameters(
        tiny_notebook(tmp_path_factory.mktemp("nb") / "p.ipynb", parameters=CELL, body="pass")
    )


def test_casts_and_annotations_give_the_default_its_type(params):
    assert params["n"] == 2 and type(params["n"]) is int
    assert params["x"] == 1e-3 and type(params["x"]) is float
    assert params["flag"] is False and params["label"] == "5"
    assert params["m"] == 2.0 and type(params["m"]) is float
    assert (
        isinstance(params["k"], grid.Expression)
        and params["k"].kind is int
        and params["k"] == "len([1, 2])"
    )
    assert isinstance(params["q"], grid.Expression) and params["q"].kind is float
    assert isinstance(params["expr"], grid.Expression) and params["expr"].kind is None
    assert params["plain"] == 3


@pytest.mark.parametrize(
    "name, raw, value",
    [
        ("n", "4", 4),
        ("n", " 7 ", 7),
        ("x", "0.5", 0.5),
        ("x", "2", 2.0),
        ("flag", "yes", True),
        ("label", "7", "7"),
        ("m", "3", 3.0),
        ("k", "7", 7),
        ("q", "1.5", 1.5),
        ("expr", "2.5", 2.5),
        ("expr", "text", "text"),
    ],
)
def test_values_convert_to_the_defaults_type(params, name, raw, value):
    v = grid.convert(name, raw, params[name])
    assert v == value and type(v) is type(value)


@pytest.mark.parametrize(
    "name, raw, says",
    [
        ("n", "4.5", "parameter n='4.5': expected a whole number (the notebook's default is 2)"),
        ("n", "four", "parameter n='four': expected a whole number"),
        ("n", "True", "parameter n='True': expected a whole number"),
        ("x", "nan", "parameter x='nan': expected a number"),
        ("flag", "maybe", "parameter flag='maybe': expected True or False"),
        (
            "k",
            "x",
            "parameter k='x': expected a whole number (the notebook's default is len([1, 2]))",
        ),
        ("q", "abc", "parameter q='abc': expected a number (the notebook's default is np.sqrt(2))"),
    ],
)
def test_values_that_do_not_convert_are_refused_by_name(params, name, raw, says):
    with pytest.raises(InputError) as err:
        grid.convert(name, raw, params[name])
    assert says in str(err.value) and "\n" not in str(err.value)


def test_the_notebook_gets_numbers_not_text(tmp_path, capsys):
    """A real run: the notebook asserts the types it was given."""
    pytest.importorskip("papermill")
    nb = tiny_notebook(
        tmp_path / "typed.ipynb",
        parameters="n = int(2)\nx: float = 1",
        body="assert type(n) is int and type(x) is float, (type(n), type(x))",
    )
    out = tmp_path / "out"
    assert (
        cli.main(
            [
                "grid",
                str(nb),
                "--param",
                "n=4",
                "--param",
                "x=3",
                "--out",
                str(out),
                "--workers",
                "1",
            ]
        )
        == 0
    )
    rows = pd.read_csv(out / "grid.csv")
    assert list(rows["status"]) == ["ok (no results file)"] and list(rows["n"]) == [4]
    capsys.readouterr()
    assert (
        cli.main(
            [
                "grid",
                str(nb),
                "--param",
                "n=4,four",
                "--out",
                str(tmp_path / "no"),
                "--workers",
                "1",
            ]
        )
        == 2
    )
    err = capsys.readouterr().err.strip()
    assert (
        err
        == (
            "navbook grid: error: grid: parameter n='four': expected a whole number (the notebook's default "
            "is 2)"
        )
        and not (tmp_path / "no").exists()
    )
