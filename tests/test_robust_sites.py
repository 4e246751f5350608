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
from navlib.workbench import calibration as C
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
    assert cli.site_argument(["field", "--site", "-1,2", "--", "--site", "-3,4"]) == \
        ["field", "--site=-1,2", "--", "--site", "-3,4"]
    with pytest.raises(SystemExit) as stop:
        cli.main(["field", "--site", "--json"])
    assert stop.value.code == 2 and "--site: expected one argument" in capsys.readouterr().err


@pytest.fixture(scope="module")
def sim():
    return MF.simulate_free({"hard_x_ut": 5.0, "scale_x": 0.02}, duration_s=20.0, noise_ut=0.3,
                            seed=np.random.SeedSequence(6)).drop(columns=list(MF.DERIVED))


def test_a_negative_latitude_for_calibrate_and_a_pole_in_its_json(sim, tmp_path, capsys):
    p = tmp_path / "sim.csv"
    sim.to_csv(p, index=False)
    rc, out, err = _run(capsys, "calibrate", "magnetometer", str(p), "--site", "-33.9,18.4",
                        "--out", str(tmp_path / "south.json"))
    assert rc == 0, err
    assert strict_json((tmp_path / "south.json").read_text())["field"]["model"]["lat_deg"] == -33.9
    rc, out, err = _run(capsys, "calibrate", "magnetometer", str(p), "--site", "90,0", "--out", str(tmp_path / "pole.json"))
    assert rc == 0, err
    model = strict_json((tmp_path / "pole.json").read_text())["field"]["model"]
    assert model["declination_deg"] is None and "geographic pole" in model["note"]
    assert np.isfinite(model["intensity_ut"]) and np.isfinite(model["dip_deg"])


@pytest.mark.parametrize("lons, expect", [
    ((179.99, -179.99), 180.0), ((-179.99, 179.99), -180.0), ((359.99, 0.01), 360.0), ((10.0, 10.05), 10.025),
])
def test_a_site_on_the_date_line_is_one_site(sim, lons, expect):
    frame = sim.copy()
    frame["lat_deg"] = 65.0
    frame["lon_deg"] = np.resize(lons, len(frame))
    site = MF.site_of(frame, name="f.csv")
    assert site.lon_deg == pytest.approx(expect, abs=1e-9)
    # the field where the recording was made (0.01 deg from either value), not half a world away
    assert igrf_field(site).intensity_ut == pytest.approx(igrf_field(Site(65.0, lons[0])).intensity_ut, rel=1e-4)


def test_two_sites_across_the_date_line_are_still_two(sim):
    frame = sim.copy()
    frame["lat_deg"] = 65.0
    frame["lon_deg"] = np.resize((179.9, -179.9), len(frame))                 # 0.2 deg apart
    with pytest.raises(InputError, match=r"f.csv: column 'lon_deg' varies by 0.2 deg"):
        MF.site_of(frame, name="f.csv")
