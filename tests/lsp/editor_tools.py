"""The npm tools the editor tests drive: vscode-textmate and vscode-oniguruma (VS Code's tokenizer), @vscode/vsce.

Installed from npm into tests/.cache/ the first time. Outside CI a missing
node or npm skips the test, saying why; under CI it fails.
"""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest
from paths import TESTS_DIR

TOOLS_DIR = os.path.join(TESTS_DIR, ".cache", "vscode-tools")
MODULES = os.path.join(TOOLS_DIR, "node_modules")
PACKAGES = ("vscode-textmate@9", "vscode-oniguruma@2", "@vscode/vsce@3")
_NEEDED = (
    os.path.join(MODULES, "vscode-textmate", "package.json"),
    os.path.join(MODULES, "vscode-oniguruma", "release", "onig.wasm"),
    os.path.join(MODULES, ".bin", "vsce"),
)


def _skip_or_fail(message: str):
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def node_or_skip() -> tuple:
    """``(node, npm)``, or skip (fail in CI) if either is missing."""
    node, npm = shutil.which("node"), shutil.which("npm")
    missing = [n for n, p in (("node", node), ("npm", npm)) if p is None]
    if missing:
        _skip_or_fail(f"{' and '.join(missing)} not found, so VS Code's tokenizer and vsce cannot run here")
    return node, npm


def tools_or_skip() -> str:
    """The node_modules folder holding vscode-textmate, vscode-oniguruma and @vscode/vsce."""
    _, npm = node_or_skip()
    if not all(os.path.exists(p) for p in _NEEDED):
        os.makedirs(TOOLS_DIR, exist_ok=True)
        done = subprocess.run(
            [npm, "install", "--no-audit", "--no-fund", "--prefix", TOOLS_DIR, *PACKAGES],
            capture_output=True,
            text=True,
            timeout=900,
            check=False,
        )
        if done.returncode != 0 or not all(os.path.exists(p) for p in _NEEDED):
            _skip_or_fail(f"npm install {' '.join(PACKAGES)} failed:\n{done.stdout}\n{done.stderr}")
    return MODULES
