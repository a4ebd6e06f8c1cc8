"""A mechanism in motion: its links, pairs and force vectors frame by frame, with the curves
of chosen outputs running beside it, written as a self-contained HTML page with a time
slider (:mod:`.page`) and as an animated GIF or MP4 (:mod:`.movie`).

The frames (:mod:`.frames`) are the drawings' poses (:func:`dyadfmu.report.drivers_drawing.pose`)
of the mechanism FMU's own outputs at each instant; where the FMU has no answer the frame
says why. Where the outputs come from (:mod:`.sources`): a harness run of a shipped
mechanism, a scene driven by a motion law, or a recorded output file of any simulator.
The command: ``dyadfmu animate`` (:mod:`.command`)."""
