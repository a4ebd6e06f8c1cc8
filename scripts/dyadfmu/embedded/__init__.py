"""Scenes on embedded targets: a scene's bundle built as Cortex-M4F firmware in float and
run under QEMU, against the same program built for this machine (``dyadfmu embedded``)."""
