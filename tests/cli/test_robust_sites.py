"""Sites (issue 35, items 6 and 8): every ``--json`` output is valid JSON (at a geographic pole the
declination is null, with a note, never NaN); a site on the date line is one site (longitudes compared on
the circle); ``--site -33.9,18.4`` and ``--site=-33.9,18.4`` both work; and a message about a site or a
date names what the user gave: the option, or the file and its column."""

import json

import numpy as np
import pytest

from navlib import cli
from navlib.errors import InputError
from navlib.sensors.earth_field import Site, igrf_field
from navlib.workbench import free_simulation as FS
from navlib.workbench import magnetometer_free as MF


def strict_json(text: str):
    """``json.loads`` that refuses NaN and infinity (not JSON)."""

    def refuse(token):
        raise ValueError(f"not JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def _run(capsys, *args):
    capsys.readouterr()
    rc = cli.main(list(args))
    out = capsys.readouterr()
    return rc, out.out, out.err.strip()


@pytest.mark.parametrize("lat", [90.0, -90.0])
def test_the_field_at_a_pole_is_valid_json_with_a_note(capsys, lat):
    rc, out, err = _run(capsys, "field", f"--site={lat:g},0", "--json")
    assert rc == 0 and err == ""
    f = strict_json(out)
    assert f["declination_deg"] is None and f["north_ut"] is None and f["east_ut"] is None
    assert "geographic pole" in f["note"] and "declination" in f["note"]
    # the rest is the limit at the pole: the field a step of 1e-6 deg away (any meridian)
    for lon in (0.0, 123.0):
        near = igrf_field(Site(np.copysign(90 - 1e-6, lat), lon)).to_dict()
        for k in ("horizontal_ut", "down_ut", "intensity_ut", "dip_deg"):
            assert f[k] == pytest.approx(near[k], rel=1e-6), k
    rc, text, _ = _run(capsys, "field", f"--site={lat:g},0")
    assert rc == 0 and "declination undefined" in text and "nan" not in text.lower()


@pytest.mark.parametrize("site", ["50,10", "89.9999,10", "-33.9,18.4,120", "0,-179.99"])
def test_the_field_elsewhere_is_valid_json_with_a_declination(capsys, site):
    rc, out, _ = _run(capsys, "field", f"--site={site}", "--json")
    f = strict_json(out)
    assert rc == 0 and isinstance(f["declination_deg"], float) and "note" not in f


def test_a_negative_latitude_in_both_forms(capsys):
    rc1, spaced, err1 = _run(capsys, "field", "--site", "-33.9,18.4", "--json")
    rc2, joined, err2 = _run(capsys, "field", "--site=-33.9,18.4", "--json")
    assert rc1 == rc2 == 0 and err1 == err2 == "" and spaced == joined
    assert (strict_json(spaced)["lat_deg"], strict_json(spaced)["lon_deg"]) == (-33.9, 18.4)
    rc, out, _ = _run(capsys, "field", "--site", "-.5,-18.4,200", "--date", "2020-01-01", "--json")
    assert rc == 0 and strict_json(out)["lat_deg"] == -0.5 and strict_json(out)["height_m"] == 200.0
    # only the value of --site is joined; a missing value is still refused by argparse
    assert cli.site_argument(["field", "--site", "-1,2", "--", "--site", "-3,4"]) == [
        "field",
        "--site=-1,2",
        "--",
        "--site",
        "-3,4",
    ]
    with pytest.raises(SystemExit) as stop:
        cli.main(["field", "--site", "--json"])
    assert stop.value.code == 2 and "--site: expected one argument" in capsys.readouterr().err


@pytest.fixture(scope="module")
def sim():
    return FS.simulate_free(
        {"hard_x_ut": 5.0, "scale_x": 0.02},
        duration_s=20.0,
        noise_ut=0.3,
        seed=np.random.SeedSequence(6),
    ).drop(columns=list(MF.DERIVED))


def test_a_negative_latitude_for_calibrate_and_a_pole_in_its_json(sim, tmp_path, capsys):
    p = tmp_path / "sim.csv"
    sim.to_csv(p, index=False)
    rc, out, err = _run(
        capsys,
        "calibrate",
        "magnetometer",
        str(p),
        "--site",
        "-33.9,18.4",
        "--out",
        str(tmp_path / "south.json"),
    )
    assert rc == 0, err
    assert strict_json((tmp_path / "south.json").read_text())["field"]["model"]["lat_deg"] == -33.9
    rc, out, err = _run(
        capsys,
        "calibrate",
        "magnetometer",
        str(p),
        "--site",
        "90,0",
        "--out",
        str(tmp_path / "pole.json"),
    )
    assert rc == 0, err
    model = strict_json((tmp_path / "pole.json").read_text())["field"]["model"]
    assert model["declination_deg"] is None and "geographic pole" in model["note"]
    assert np.isfinite(model["intensity_ut"]) and np.isfinite(model["dip_deg"])


@pytest.mark.parametrize(
    "lons, expect",
    [
        ((179.99, -179.99), 180.0),
        ((-179.99, 179.99), -180.0),
        ((359.99, 0.01), 360.0),
        ((10.0, 10.05), 10.025),
    ],
)
def test_a_site_on_the_date_line_is_one_site(sim, lons, expect):
    frame = sim.copy()
    frame["lat_deg"] = 65.0
    frame["lon_deg"] = np.resize(lons, len(frame))
    site = MF.site_of(frame, name="f.csv")
    assert site.lon_deg == pytest.approx(expect, abs=1e-9)
    # the field where the recording was made (0.01 deg from either value), not half a world away
    assert igrf_field(site).intensity_ut == pytest.approx(
        igrf_field(Site(65.0, lons[0])).intensity_ut, rel=1e-4
    )


def test_two_sites_across_the_date_line_are_still_two(sim):
    frame = sim.copy()
    frame["lat_deg"] = 65.0
    frame["lon_deg"] = np.resize((179.9, -179.9), len(frame))  # 0.2 deg apart
    with pytest.raises(InputError, match=r"f.csv: column 'lon_deg' varies by 0.2 deg"):
        MF.site_of(frame, name="f.csv")


# ------------------------------------------------------------------------- item 8: who is blamed
def _file(tmp_path, sim, name="rec.csv", **cols):
    frame = sim.copy()
    for k, v in cols.items():
        frame[k] = v
    p = tmp_path / name
    frame.to_csv(p, index=False)
    return p


def test_a_date_column_without_a_site_names_the_file_and_column(sim, tmp_path, capsys, monkeypatch):
    import navlib.commands

    def no_loop(*a, **k):
        raise AssertionError("the loop ran before the site was checked")

    monkeypatch.setattr(navlib.commands, "loop", no_loop)
    p = _file(tmp_path, sim, date="2021-01-01")
    for args in (
        ["calibrate", "magnetometer", str(p), "--out", str(tmp_path / "c.json")],
        ["loop", "magnetometer_free", str(p), "--model", "hard_iron"],
    ):
        rc, _, err = _run(capsys, *args)
        assert rc == 2 and len(err.splitlines()) == 1, err
        assert "rec.csv: column 'date' without a site" in err and "--date" not in err, err
    assert not (tmp_path / "c.json").exists()
    # the same file with --site is fine; --date without any site blames --date, which the user gave
    rc, _, err = _run(
        capsys,
        "calibrate",
        "magnetometer",
        str(p),
        "--site",
        "50,10",
        "--out",
        str(tmp_path / "ok.json"),
    )
    assert rc == 0, err
    rc, _, err = _run(
        capsys,
        "calibrate",
        "magnetometer",
        str(_file(tmp_path, sim, "plain.csv")),
        "--date",
        "2020-01-01",
        "--out",
        str(tmp_path / "c.json"),
    )
    assert rc == 2 and err.endswith(
        "error: parameter --date: a date without a site: give --site LAT,LON[,HEIGHT_M] "
        "or the columns lat_deg, lon_deg"
    ), err


def test_a_date_column_outside_igrf_names_the_file_column_and_row(sim, tmp_path, capsys):
    dates = np.full(len(sim), "2021-01-01", dtype=object)
    dates[4] = "2031-06-01"
    p = _file(tmp_path, sim, lat_deg=50.0, lon_deg=10.0, date=dates)
    rc, _, err = _run(
        capsys, "calibrate", "magnetometer", str(p), "--out", str(tmp_path / "c.json")
    )
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert (
        "rec.csv: column 'date', row 5: '2031-06-01' is outside the model's years (IGRF-14 covers"
        in err
    ), err
    assert "parameter" not in err


@pytest.mark.parametrize(
    "args, says",
    [
        (["--site", "95,0"], "parameter --site='95,0': the latitude must be <= 90"),
        (["--site", "nan,0"], "parameter --site='nan,0': the latitude must be finite"),
        (["--site", "10,400"], "parameter --site='10,400': the longitude must be <= 360"),
        (["--site", "10,20,-2e4"], "parameter --site='10,20,-2e4': the height must be >= -10000"),
        (
            ["--site", "10,20", "--date", "2040-01-01"],
            "parameter --date='2040-01-01': IGRF-14 covers",
        ),
        (["--site", "10,20", "--date", "soon"], "parameter --date='soon': not a date"),
    ],
)
def test_site_and_date_options_are_named_as_given_and_checked_before_the_work(
    sim, tmp_path, capsys, args, says
):
    p = _file(tmp_path, sim)
    for command in (
        ["field"],
        ["calibrate", "magnetometer", str(p), "--out", str(tmp_path / "c.json")],
    ):
        rc, _, err = _run(capsys, *command, *args)
        assert rc == 2 and len(err.splitlines()) == 1 and says in err, err
        assert "lat_deg" not in err and "parameter date=" not in err
    assert not (tmp_path / "c.json").exists()


def test_a_frame_read_from_a_file_is_named_by_it(sim, tmp_path):
    from navlib.workbench.magnetometer_free import load_free

    frame = load_free(_file(tmp_path, sim, "named.csv", date="2021-01-01"))
    with pytest.raises(InputError, match="^named.csv: column 'date' without a site"):
        MF.site_of(frame)
