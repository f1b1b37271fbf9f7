"""The example of docs/python.md runs and finds the contact it describes."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import python_env

pytestmark = pytest.mark.preprocess

DOC = Path(__file__).resolve().parents[2] / "docs" / "python.md"


def test_pawn_example_runs(tmp_path):
    text = DOC.read_text()
    section = text[text.index("## Example"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=python_env(), capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert re.search(r"step 22: first contact at t = 0\.\d+ \(vertex-face", result.stdout), \
        result.stdout
    assert "median" in result.stdout
