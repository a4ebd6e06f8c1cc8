"""Reports: tables, plots and drawings, and the written reports of the study, the
co-simulation and the scenes."""
