"""The layering of the package is a contract the build checks, not a description.

- import-linter's contracts in ``pyproject.toml`` (layers core -> ... -> app; the
  checker imports nothing it checks, and not numpy) hold;
- ``import intervalkin`` and ``import intervalkin.checker`` stay light: neither
  loads numpy nor the paving code, so the checker is independent of what it checks;
- no module grows past the size where it stops holding one concept;
- a helper shared between modules is public where it lives: no module imports another's
  private (``_name``) definitions.
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "intervalkin"
MAX_LINES = 420


def test_import_contracts_hold():
    exe = shutil.which("lint-imports")
    if exe is None:
        pytest.fail("lint-imports is not installed: the test extra of pyproject.toml must install import-linter")
    proc = subprocess.run([exe, "--config", str(ROOT / "pyproject.toml")], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.mark.parametrize("module", ["intervalkin", "intervalkin.checker"])
def test_light_imports(module):
    code = (f"import sys, {module}\n"
            "heavy = [m for m in ('numpy', 'intervalkin.paving', 'intervalkin.kinematics', 'matplotlib') if m in sys.modules]\n"
            "print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "", f"import {module} loaded {out}"


def test_modules_hold_one_concept_each():
    long = {str(p.relative_to(PACKAGE)): n for p in PACKAGE.rglob("*.py")
            if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_layers_are_folders():
    layers = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert {"core", "kinematics", "paving", "solve", "space", "certify", "checker", "app"} <= layers
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert loose == ["__init__.py", "__main__.py", "pipeline.py"], loose


def test_no_module_imports_a_private_name_of_another():
    found = {}
    for p in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("intervalkin"):
                names = {a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")}
                if names:
                    found.setdefault(str(p.relative_to(PACKAGE)), set()).update(names)
    assert not found, found
