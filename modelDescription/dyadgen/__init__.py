"""dyadgen: everything an FMU of dyadfmu needs, generated from its single source.

The source is a scene file (modelDescription/scenes/README.md: a crank and a chain of Assur dyads,
their effects, outputs and tunable parameters) or, for the crank drive and the motor, a
variable table (interface/drive.toml, interface/motor.toml). The generator works in
stages, each module in one of them:

    scenefile/   read and check a scene: every problem with its file and line
    model, needs the mechanism (links, dyads, pairs, crank) and what the wanted
                 outputs need (the derived inputs and outputs)
    table        the interface table: variables, value references, dependencies,
                 validated, and the instantiation token
    settings     what the FMU layer itself reads (on_singular), the same in every kind
    kinds        one object per kind of model (generic dyad, tailored scene, drive, motor):
                 its structures, its table, its source files, its C and documentation
    emit/        the generated files: both model descriptions, the build description,
                 the C variable table, a scene's C, the documentation pages
    pipeline     the stages joined, as the command-line entry points use them

Python 3.11 standard library only.
"""
