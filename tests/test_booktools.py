import nbformat

from navlib.booktools import check_html, missing_figures, strip_metadata


def test_check_html_flags_remote_assets(tmp_path):
    (tmp_path / "ok.html").write_text('<script src="_static/mathjax/tex-chtml.js"></script>')
    assert check_html(tmp_path) == 0
    (tmp_path / "bad.html").write_text('<script src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex.js"></script>')
    assert check_html(tmp_path) == 1


def test_check_html_flags_tracebacks(tmp_path):
    (tmp_path / "p.html").write_text("<pre>Traceback (most recent call last):</pre>")
    assert check_html(tmp_path) == 1


def test_strip_metadata_removes_timings():
    nb = nbformat.v4.new_notebook()
    nb.metadata["papermill"] = {"duration": 1.0}
    cell = nbformat.v4.new_code_cell("1")
    cell.metadata["papermill"] = {"duration": 0.1}
    cell.metadata["execution"] = {"iopub.status.busy": "x"}
    cell.execution_count = 3
    nb.cells.append(cell)
    strip_metadata(nb)
    assert "papermill" not in nb.metadata and cell.metadata == {}
    assert cell.execution_count == 3          # nbval needs execution counts to compare outputs


def test_missing_figures_detects_plot_cells_without_images():
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell("plt.plot([1]); plt.show()")
    nb.cells.append(cell)
    assert missing_figures(nb) == [0]
    cell.outputs = [nbformat.v4.new_output("display_data", data={"image/png": "iVBOR"})]
    assert missing_figures(nb) == []


def test_execute_fails_loudly_on_a_failing_notebook(tmp_path, capsys):
    from navlib.booktools import execute

    nb = nbformat.v4.new_notebook()
    nb.cells.append(nbformat.v4.new_code_cell("x = 1"))
    nb.cells.append(nbformat.v4.new_code_cell("raise ValueError('parameter NP=3: must be >= 4')"))
    path = tmp_path / "bad.ipynb"
    nbformat.write(nb, path)
    out = tmp_path / "out"
    assert execute([path], out, in_place=False) == 1
    assert "FAILED bad.ipynb" in capsys.readouterr().err
    assert not (out / "bad.ipynb").exists()          # no half-executed notebook lands in the book
