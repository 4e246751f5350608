"""navbook's tooling: what builds and checks the book, kept out of the library users install.

The package lives beside the book (``book/navbook``) and is installed into the book's environment only
(``make venv``: ``pip install -e book``); a plain ``pip install .`` of navlib contains none of it.

- :mod:`navbook.report`: what a chapter notebook calls to show its results: HTML tables that fit the page,
  numbers glued into the prose, the claims at a glance, the chapter's results file.
- :mod:`navbook.booktools`: execute the chapters (papermill), check the built HTML, write the landing page and
  the API pages, compare results files, take screenshots.
- :mod:`navbook.grid`: a chapter over a grid of its parameters.
- :mod:`navbook.cli`: ``python -m navbook COMMAND`` (the Makefile's steps).
"""
