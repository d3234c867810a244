"""Design sweeps: one certified analysis per design of a family of 3-RPR manipulators, as Dask tasks.

spec      the sweep file (TOML): a base geometry, the parameters to vary, the analysis settings;
          its designs, each with the content hash that keys its cached result
task      one design analysed (runs on a Dask worker): counts with their certified bounds, volumes,
          time, memory; a design that fails is a result with its error, not an exception
engine    the sweep itself: a Dask client (a LocalCluster sized to the machine, or a scheduler
          address), the cache of results by content hash, resuming, the returned table
table     the results table (one row per design): columns, CSV and Parquet, the best designs

This layer sits above :mod:`intervalkin.pipeline` and below :mod:`intervalkin.app`.  Nothing
here is imported by ``import intervalkin``: :func:`intervalkin.sweep` loads it on first use, and
Dask itself is imported only when a sweep runs.
"""
