"""Data loading with validation: CSV tables whose every fault is reported with file, column and row.

- :mod:`navlib.data.tables` -- generic validated CSV reading (:func:`.tables.read_table`) and safe writing
  (:func:`.tables.write_new_csv`, never over an existing file);
- :mod:`navlib.data.compass_sweeps` -- turntable sweeps (papers A and B, the workbench's compass files);
- :mod:`navlib.data.gyro_tables` -- paper C's measured Tables 2-5 and user drift files;
- :mod:`navlib.data.tumble` -- accelerometer tumble files (paper D);
- :mod:`navlib.data.broad` -- the original BROAD recordings (``.mat``) converted into the workbench's
  CSV files (``python -m navlib.data.broad --in DIR --out DIR``).
"""
