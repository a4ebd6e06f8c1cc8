"""FMUs through fmpy: one instance loaded, set, stepped and read (:mod:`.slave`), and a
whole co-simulation with ``simulate_fmu`` (:mod:`.simulate`)."""
