"""The workbench chapter's "Bring your own data" (navlib.studies.workbench.own_data): the schema, sample
rows, a command that fits the column, and the report the command writes."""

import pytest

from navlib.errors import InputError
from navlib.studies import workbench as wb
from navlib.workbench.effects import columns_table


def test_own_data_sections_show_the_schema_sample_rows_and_a_command_that_fits(tmp_path):
    for system in ("compass", "drift", "accelerometer"):
        own = wb.own_data(system, rows=3)
        assert own.columns.equals(columns_table(system))
        assert list(own.sample.columns) == ["row 1", "row 2", "row 3"]
        assert set(own.sample.index) <= set(own.columns["column"])
        assert own.command.startswith(f"navlib loop {system} ") and "--report" in own.command
    assert "data/compass_sweeps.csv" in wb.own_data("compass").command
    long = wb.shell_command(
        ["navlib", "loop", "magnetometer", "x" * 70, "--report", "out/"], width=80
    )
    assert all(len(line) <= 80 + 2 for line in long.splitlines()) and long.count("\\\n") == 2
    png, md = wb.own_data_report(tmp_path / "rep")
    assert png.stat().st_size > 1000 and "| step | model |" in md.read_text()
    with pytest.raises(InputError, match="already exists"):
        wb.own_data_report(tmp_path / "rep")
    text = wb.wrap_report("| a | b |\n" + "word " * 40)
    assert max(map(len, text.splitlines())) <= 88 and text.startswith("| a | b |")
