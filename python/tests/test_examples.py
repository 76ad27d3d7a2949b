"""The examples run, and the errors they print are round-off."""

import re
import subprocess
import sys

from conftest import EXAMPLES


def test_skfem_two_boxes_prints_round_off_errors():
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / "skfem_two_boxes.py")], capture_output=True, text=True, check=True
    ).stdout
    errors = [float(e) for e in re.findall(r"max \|u − u_exact\| = (\S+) K", out)]
    assert len(errors) == 2 and max(errors) < 1e-11, out
