"""The command lines of modelDescription/generate.py and modelDescription/scene.py."""
