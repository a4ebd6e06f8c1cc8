"""Design studies over many runs: ``dyadfmu sweep STUDY.toml`` (:mod:`.study`) reads a
study file (:mod:`.studyfile`), draws its designs (:mod:`.designs`), runs each on the
FMUs (:mod:`.runs`) in this process or on Dask (:mod:`.execute`) and writes the table,
the best designs and the plots (:mod:`.results`, :mod:`dyadfmu.report.sweep`)."""
