"""The BROAD converter writes all or nothing (issue 35, item 4): a truncated trial file among good ones, an
output that appears while it works, or Ctrl-C leave the output folder as it was (the files are written into
a staging folder beside the target and moved into place at the end)."""

import os

import pytest

from navlib.data import broad, tables
from navlib.errors import InputError
from test_broad_convert import _trial, _write


@pytest.fixture(scope="module")
def arrays():
    return _trial(seconds=30.0, heading_rate_dps=30.0, tilt_deg=3.0)[0]


def _folder(tmp_path, arrays, truncated: str | None = None):
    src = tmp_path / "data_mat"
    for name in (
        "05_undisturbed_slow_rotation_with_breaks_B.mat",
        "28_disturbed_stationary_magnet_A.mat",
        "30_disturbed_stationary_magnet_C.mat",
    ):
        p = _write(src, name, arrays)
        if name.startswith(truncated or "-"):
            data = p.read_bytes()
            p.write_bytes(data[: len(data) // 2])  # cut off mid-file
    return src


def _tree(folder):
    return (
        sorted(str(p.relative_to(folder)) for p in folder.rglob("*")) if folder.exists() else None
    )


def test_a_truncated_trial_file_writes_nothing(tmp_path, arrays, capsys):
    src = _folder(tmp_path, arrays, truncated="30_")
    out = tmp_path / "out"
    assert broad.main(["--in", str(src), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "30_disturbed_stationary_magnet_C.mat" in err, err
    assert not out.exists() and os.listdir(tmp_path) == [
        "data_mat"
    ]  # no staging folder left either
    # into an existing folder with files of its own: untouched, no staging folder left
    mine = tmp_path / "mine"
    (mine / "3d").mkdir(parents=True)
    (mine / "3d" / "notes.txt").write_text("mine")
    before = _tree(mine)
    assert broad.main(["--in", str(src), "--out", str(mine)]) == 2
    assert _tree(mine) == before and (mine / "3d" / "notes.txt").read_text() == "mine"


def test_a_complete_conversion_into_an_existing_folder(tmp_path, arrays):
    src = _folder(tmp_path, arrays)
    out = tmp_path / "out"
    (out / "3d").mkdir(parents=True)
    (out / "3d" / "notes.txt").write_text("mine")
    written = broad.convert(src, out, trials=[5, 28])
    assert [p.relative_to(out).as_posix() for p in written] == [
        "3d/broad_05_undisturbed_slow_rotation_with_breaks_B.csv",
        "level/broad_trial05_level.csv",
        "3d/broad_28_stationary_magnet_A.csv",
        "level/broad_trial28_level.csv",
    ]
    assert all(p.is_file() and p.stat().st_size > 100 for p in written)
    assert _tree(out) == sorted(
        ["3d", "3d/notes.txt", "level"] + [p.relative_to(out).as_posix() for p in written]
    )


def test_an_output_that_appears_meanwhile_is_not_overwritten_and_nothing_is_written(
    tmp_path, arrays, monkeypatch
):
    src = _folder(tmp_path, arrays)
    out = tmp_path / "out"
    out.mkdir()
    late = out / "level" / "broad_trial28_level.csv"
    real = broad.read_trial

    def read_and_someone_writes(p):
        if p.name.startswith("30_"):
            late.parent.mkdir(exist_ok=True)
            late.write_text("someone else's")
        return real(p)

    monkeypatch.setattr(broad, "read_trial", read_and_someone_writes)
    with pytest.raises(
        InputError, match=f"{late}: already exists; not overwritten .*nothing written"
    ):
        broad.convert(src, out)
    assert (
        _tree(out) == ["level", "level/broad_trial28_level.csv"]
        and late.read_text() == "someone else's"
    )


def test_ctrl_c_in_the_middle_writes_nothing(tmp_path, arrays, monkeypatch):
    src = _folder(tmp_path, arrays)
    out = tmp_path / "out"
    real = broad.level_sweep

    def interrupted(trial, number=None, **k):
        if number == 28:
            raise KeyboardInterrupt
        return real(trial, number, **k)

    monkeypatch.setattr(broad, "level_sweep", interrupted)
    with pytest.raises(KeyboardInterrupt):
        broad.convert(src, out)
    assert not out.exists() and os.listdir(tmp_path) == ["data_mat"]


def test_publish_places_files_without_links_too(tmp_path, monkeypatch):
    """Where hard links are refused, publish copies (never over a file)."""
    staging = tables.staging_folder(tmp_path / "t")
    (staging / "a").mkdir()
    (staging / "a" / "x.csv").write_text("1")
    target = tmp_path / "t"
    target.mkdir()

    def no_links(src, dst):
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_links)
    assert tables.publish(staging, target) == {staging / "a" / "x.csv": target / "a" / "x.csv"}
    assert (target / "a" / "x.csv").read_text() == "1"
