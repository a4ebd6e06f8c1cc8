"""Reading and checking a scene file (modelDescription/scenes/README.md): the locator that finds the
line of every table and key, one parser per TOML section, the rules for names, and the C
names a scene's names must not clash with. A malformed scene is rejected with every
problem, each naming the file, the line and what is wrong; nothing is written."""
