"""Measurements: the accuracy and speed study (:mod:`.accuracy` on the inputs of
:mod:`.configurations`, with :mod:`.bench`), the tailored FMUs' footprint
(:mod:`.footprint`) and the scene generator's timing on long chains (:mod:`.long_chain`)."""
