"""The tests drive the scikit-fem host of python/examples/skfem_two_boxes.py."""

import pathlib
import sys

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))
