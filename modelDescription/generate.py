#!/usr/bin/env python3
"""Generate everything an FMU of one model needs from its variable table.

The table (interface/drive.toml for the crank drive, interface/motor.toml for the motor;
a generic dyad's comes from its scene) is the single source of truth for the interface of
one FMU: names, value references, causalities, units, start values, bounds, descriptions,
where each value lives in the model's structures and which inputs each output depends on.
From it this script writes

    DIR/fmi2/modelDescription.xml      the FMI 2.0 model description
    DIR/fmi3/modelDescription.xml      the FMI 3.0 model description
    DIR/fmi3/buildDescription.xml      the FMI 3.0 build description
    DIR/<identifier>_model.c           the C variable table (see fmu/fmu_model.h)
    DIR/documentation/index.html       the FMU's documentation page

Usage:
    generate.py TABLE.toml --out DIR   generate the files of one table
    generate.py --update-golden        rewrite modelDescription/interface/golden/*.xml
    generate.py --check-golden         exit 1 with a diff if a golden file differs

The table is validated first; every problem is reported with the file and the
variable it concerns, and nothing is written unless the table is valid. The work is
done by the package dyadgen (dyadgen/__init__.py describes its stages).

Python 3.11 standard library only.
"""

import sys

from dyadgen.cli.generate import main

if __name__ == "__main__":
    sys.exit(main())
