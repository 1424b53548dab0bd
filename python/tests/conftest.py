import os
import sys

# The suites import the shared test meshes and oracle as a plain module.
sys.path.insert(0, os.path.dirname(__file__))
