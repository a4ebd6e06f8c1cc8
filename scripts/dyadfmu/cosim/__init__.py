"""Co-simulations checked against references: a mechanism's dyad FMU (:mod:`.harness`), a
scene's tailored FMU (:mod:`.scenes`), the drive and dyad FMUs in a closed loop
(:mod:`.master`), and every FMU through a second importer (:mod:`.importers`)."""
