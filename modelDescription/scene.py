#!/usr/bin/env python3
"""Turn a scene into a tailored FMU: its variable table, its C model, both model
descriptions and its documentation.

A scene (TOML, see modelDescription/scenes/README.md for the schema) describes a mechanism: an
optional crank and a chain of Assur dyads, how each dyad's external links k and
p connect (the frame, the crank, a link of an earlier dyad, or an external link
whose motion is an input), which effects are present (inertia, gravity, active
forces and moments on which links), which outputs are wanted and which
parameters stay tunable (all others are baked into the C code as constants).

From it the package dyadgen derives the FMU's variables (only those the scene needs)
and generates C that computes only what the scene needs (dyadgen/emit/scene_c.py).

Usage:
    scene.py SCENE.toml --out DIR    generate the FMU's files (see generate.py)
    scene.py SCENE.toml --check      validate only; print the variable counts
    scene.py SCENE.toml --cmake-info print 'identifier;realisation;lanes;types...' for CMake

A malformed scene is rejected with every problem, each naming the file, the line
and what is wrong; nothing is written.

Python 3.11 standard library only.
"""

import sys

from dyadgen.cli.scene import main

if __name__ == "__main__":
    sys.exit(main())
