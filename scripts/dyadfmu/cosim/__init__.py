"""Co-simulations checked against references: a mechanism's dyad FMU (:mod:`.harness`), a
scene's tailored FMU (:mod:`.scenes`), the drive and dyad FMUs in a closed loop
(:mod:`.master`), and every FMU through a second importer (:mod:`.importers`)."""

#: The tailored example scenes, in the order of the report (:mod:`.scenes`; here, where
#: the command line's help reads them without importing the co-simulations).
SCENE_NAMES = ("press", "monitor", "engine", "shaper", "sixbar", "rocker_slider")
