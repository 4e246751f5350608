"""The book's data files (CSV tables and their dictionaries, see README.md), shipped with navlib as the package
``navlib._data``; read them with :func:`navlib.paths.data_path`."""
