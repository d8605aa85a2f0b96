import os
import sys

import matplotlib

matplotlib.use("Agg")

# Make the reference helpers importable as plain modules.
sys.path.insert(0, os.path.dirname(__file__))
