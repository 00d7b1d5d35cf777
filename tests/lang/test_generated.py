"""The generated-file command line of lang/ (lang/generated.py): check only reports, a write replaces the file whole."""

from __future__ import annotations

import os
import stat

from liganimate.lang.generated import regenerate


def test_check_reports_a_stale_file_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "made.txt"
    path.write_text("old\n", encoding="utf-8")
    assert regenerate(["--check"], "made", [(path, lambda: "new\n")], "") == 1
    assert path.read_text(encoding="utf-8") == "old\n"
    assert "is stale: run python -m made" in capsys.readouterr().err


def test_a_file_is_written_in_order_keeping_its_mode(tmp_path):
    first, second = tmp_path / "first.txt", tmp_path / "second.txt"
    first.write_text("old\n", encoding="utf-8")
    os.chmod(first, 0o664)
    # The second file is made from the first as written now (as the tables are made from lig.lark).
    files = [(first, lambda: "new\n"), (second, lambda: first.read_text(encoding="utf-8").upper())]
    assert regenerate([], "made", files, "") == 0
    assert first.read_text(encoding="utf-8") == "new\n" and second.read_text(encoding="utf-8") == "NEW\n"
    # Not the owner-only mode of the temporary file it was written as.
    assert stat.S_IMODE(first.stat().st_mode) == 0o664
    assert stat.S_IMODE(second.stat().st_mode) == 0o644
    assert sorted(p.name for p in tmp_path.iterdir()) == ["first.txt", "second.txt"]
    assert regenerate(["--check"], "made", files[:1], "") == 0
