"""How the book shows results: HTML tables that fit the page, numbers glued into the prose, captioned
figures, the chapter's claims with their verdicts, and the headline results file of each chapter.

A chapter notebook uses it like this::

    from navbook import report
    report.use_style()      # figures for the 756 px column, 11-12 pt;
                            # tables with readable labels
    # an HTML table (text/plain kept for nbval)
    report.table(df, formats={"rms (deg)": "{:.3f}"})
    # prose: {glue:text}`ade_rms`
    report.glue_number("ade_rms", 4.23, "{:.2f}")
    # markdown: ```{glue:figure} fig-compass-errors
    report.glue_figure("fig-compass-errors", fig)
    d = verdicts.paired_difference(rms_de, rms_ade)       # the same seeds
    claims = [report.Claim(
        "ADE-BP beats DE-BP", "-0.22..0.20 vs -0.31..0.25 deg", reading="pure DE",
        statistic="RMS DE-BP - RMS ADE-BP, deg", estimate=d, boundary=0.0,
        holds_when="above", unit="deg")]
    # Results at a glance (chapter top)
    report.glue_table("compass_glance", report.glance(claims))
    report.write_results("compass", claims=claims, unit="deg",
                         methods={"ADE-BP": report.method_stats(rms, mins, maxs)})

Every verdict follows from the claim's interval by the one rule of :mod:`navlib.verdicts`.  Every number
shown comes from the code that ran; nothing is typed in.  Rounding happens here, so stored
notebook outputs compare within tolerance (nbval).

The functions live in one module per job; this module is the notebooks' one name for them all:

- :mod:`navbook.tables`: :func:`~navbook.tables.table` (HTML with a plain-text twin), readable labels,
  :func:`~navbook.tables.parameter_table`, :func:`~navbook.tables.use_style` and
  :func:`~navbook.tables.fold_tables` (the switches ``READABLE_TABLES`` and ``FOLD_TABLES`` live there).
- :mod:`navbook.claim_boxes`: :func:`~navbook.claim_boxes.glance`, :func:`~navbook.claim_boxes.showed` and the
  answers per claims-register entry.
- :mod:`navbook.glue`: ``glue_number``, ``glue_text``, ``glue_table``, ``glue_figure``, ``glue_png``,
  ``glue_claims``.
- :mod:`navbook.results`: :func:`~navbook.results.write_results` and the readers of results files.
"""

from __future__ import annotations

# navlib's, for the chapters: report.Claim, report.method_stats, report.fmt, report.plain, the figure style
from navlib.claims import Claim, method_stats  # noqa: F401
from navlib.formatting import fmt, plain  # noqa: F401
from navlib.plotstyle import legend_below, legend_right, panel_grid, panels, staircase  # noqa: F401

from .claim_boxes import ANSWER_COLUMNS, GLANCE_COLUMNS, GLANCE_OPEN_ROWS, ON_REAL  # noqa: F401
from .claim_boxes import READING_WORDS, VERDICTS_HREF, Answer, Glance, Showed, glance, showed  # noqa: F401
from .claim_boxes import headline_sentence, reading_label, record_label, register_records  # noqa: F401
from .claim_boxes import claim_table, tally, tally_of  # noqa: F401
from .glue import glue_claims, glue_figure, glue_number, glue_png, glue_table, glue_text  # noqa: F401
from .results import METHOD_KEYS, RESULTS_ENV, claims_summary, results_dir, write_results  # noqa: F401
from .results import read_result, read_results  # noqa: F401
from .tables import ACRONYMS, PARAMETER_UNITS, PLAIN_WIDTH, UNIT_SUFFIXES, Table, table  # noqa: F401
from .tables import fold_tables, label, no_negative_zero, readable, row_label, unit_of, use_style  # noqa: F401
from .tables import parameter_rows, parameter_table  # noqa: F401
