"""navbook's tooling: what builds and checks the book, kept out of the library users install.

The package lives beside the book (``book/navbook``) and is installed into the book's environment only
(``make venv``: ``pip install -e book``); a plain ``pip install .`` of navlib contains none of it.

- :mod:`navbook.report`: what a chapter notebook calls to show its results (one name for all of them):
  HTML tables that fit the page (:mod:`navbook.tables`), numbers glued into the prose (:mod:`navbook.glue`),
  the claims at a glance (:mod:`navbook.claim_boxes`), the chapter's results file (:mod:`navbook.results`).
- The Makefile's steps, one module per job: :mod:`navbook.execute` (execute the chapters with papermill),
  :mod:`navbook.html_checks` (check the built HTML), :mod:`navbook.landing` (the landing page's status from
  the results files), :mod:`navbook.api_pages` (the API reference pages), :mod:`navbook.results_check`
  (results files against the rule and the committed references), :mod:`navbook.screenshots` (every page
  rendered with headless Chromium), :mod:`navbook.kernels` (compile the numba kernels once).
- :mod:`navbook.grid`: a chapter over a grid of its parameters.
- :mod:`navbook.cli`: ``python -m navbook COMMAND`` (the Makefile's steps).
"""
