"""The VS Code extension in editors/vscode/ is packaged as a .vsix by vsce, VS Code's own packaging tool.

The extension's one dependency (vscode-languageclient) is installed from
its lock file, as a user's build would, and vsce refuses a package whose
manifest, files or dependencies are wrong. The .vsix is then opened and
its manifest read back: the language, the grammar and the client that
starts ``liganimate lsp`` are in it.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import zipfile

from editor_tools import node_or_skip, tools_or_skip
from paths import ROOT_DIR

EXTENSION = os.path.join(ROOT_DIR, "editors", "vscode")


def test_vsce_packages_the_extension(tmp_path):
    modules = tools_or_skip()
    node, npm = node_or_skip()
    work = tmp_path / "vscode"
    shutil.copytree(EXTENSION, work, ignore=shutil.ignore_patterns("node_modules", "*.vsix"))
    done = subprocess.run(
        [npm, "ci", "--no-audit", "--no-fund", "--omit=dev"],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    vsix = tmp_path / "liganimate.vsix"
    done = subprocess.run(
        [node, os.path.join(modules, "@vscode", "vsce", "vsce"), "package", "--out", str(vsix)],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    with zipfile.ZipFile(vsix) as z:
        names = set(z.namelist())
        manifest = json.loads(z.read("extension/package.json"))
        grammar = json.loads(z.read("extension/syntaxes/lig.tmLanguage.json"))
        client = z.read("extension/extension.js").decode("utf-8")
        vsix_manifest = z.read("extension.vsixmanifest").decode("utf-8")
    assert manifest["contributes"]["languages"][0]["id"] == "lig"
    assert manifest["contributes"]["languages"][0]["extensions"] == [".lig"]
    assert manifest["contributes"]["grammars"][0]["scopeName"] == grammar["scopeName"] == "source.lig"
    assert "extension/" + manifest["contributes"]["grammars"][0]["path"].removeprefix("./") in names
    assert "extension/language-configuration.json" in names
    assert "extension/node_modules/vscode-languageclient/node.js" in names
    assert 'args: ["lsp"]' in client and "vscode-languageclient/node" in client
    assert "LIG ANIMATE" in vsix_manifest
    # The client is JavaScript node can parse.
    check = subprocess.run([node, "--check", str(work / "extension.js")], capture_output=True, text=True, timeout=60)
    assert check.returncode == 0, check.stderr
