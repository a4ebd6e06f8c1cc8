"""The generated files of one FMU, each from its interface table (and, for a tailored
scene's C, from its model): the FMI 2.0 and 3.0 model descriptions, the FMI 3.0 build
description, the C variable table (fmu/fmu_model.h), a scene's C and header, and the
documentation page. Every user text reaches them through textsafe."""
