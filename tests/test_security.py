"""Hostile input: program text, file names and cache files never run as Python; LOAD never shows a foreign file.

See docs/security.md for the trust model these tests hold the code to.
"""

from __future__ import annotations

import json
import os
import pickle
import re
import stat
import subprocess
import sys

import pytest

from liganimate.compiler import compile_file, library, library_cache
from liganimate.lang.diagnostics import LigDiagnostics

CODE = '__import__("pathlib").Path("MARKER").touch()'
POSITIONED = re.compile(r":\d+:\d+: (error|warning): ")


def cli(argv, cwd, env=None, timeout=120):
    """Run ``python *argv``; stdout and stderr decoded leniently (they may echo odd names)."""
    full = dict(os.environ)
    full.pop("LIGANIMATE_DEBUG", None)
    full.update(env or {})
    r = subprocess.run([sys.executable, *argv], check=False, cwd=cwd, env=full, capture_output=True, timeout=timeout)
    return r.returncode, r.stdout.decode("utf-8", "replace"), r.stderr.decode("utf-8", "replace")


def liganimate(*args, cwd, env=None, timeout=120):
    return cli(["-m", "liganimate", *args], cwd, env, timeout)


def no_marker(root) -> None:
    found = [str(p) for p in root.rglob("MARKER")]
    assert not found, f"program text ran as Python: {found}"


def success_or_diagnostic(result) -> None:
    code, out, err = result
    assert "Traceback" not in out + err and "internal error" not in out + err, out + err
    assert code == 0 or (code == 1 and POSITIONED.search(err)), (code, out, err)


# ------------------------------------------------------------- injection

BREAKS = ["\r", "\n", "\u2028", "\u0085"]
QUOTES = "'\"'''\"\"\"\\\\'\\\""  # ' " ''' """ \\ \' \"


def payload(brk: str) -> str:
    return f"q{QUOTES}{brk}{CODE}{brk}#"


LIB = """\
{@ CUBE: a cube }
CUBE :- BOX WIDTH 1, HEIGHT 1, DEPTH 1
"""


def program(p: str) -> str:
    """A program carrying ``p`` in every channel its text has: comments, quoted words, names, numbers."""
    quoted = p.replace("\n", " ").replace("'", '"')  # what a quoted word may hold
    comment = p.replace("}", ")")
    return f"""\
{{ {comment} }}
LOAD CUBE FROM '{quoted}/../lib.lig'
LOAD 'lib/{quoted}.lig'
PRINT '{quoted}', 1.5E+3
EXEC = 1 {{ {comment} }}
EVAL = EXEC + 007 + .5 + 45°
OS :- CUBE + WEDGE
INITIALIZE SCENE 1
VIEW POINT = (0, 0, 6)
BACKGROUND OS
STARTSCENE LENGTH 1
ENDSCENE
SHOOTSCENES
"""


def every_command(folder, name: str) -> list:
    """check, run and compile the program ``name``, then run the compiled module; nothing may execute."""
    results = []
    for args in (
        ("check", name),
        ("run", name, "--size", "32x24", "--quiet", "-o", "out"),
        ("compile", name, "-o", "mod.py"),
    ):
        results.append(liganimate(*args, cwd=folder))
        success_or_diagnostic(results[-1])
        no_marker(folder)
    if (folder / "mod.py").exists():
        results.append(cli(["mod.py", "-o", "out2", "--size", "32x24", "--quiet"], folder))
        success_or_diagnostic(results[-1])
        no_marker(folder)
    return results


@pytest.mark.parametrize("brk", BREAKS, ids=["cr", "lf", "u2028", "u0085"])
def test_no_channel_runs_python(tmp_path, brk):
    p = payload(brk)
    quoted = p.replace("\n", " ").replace("'", '"')
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib.lig").write_text(LIB)
    # The library's file name and its own text carry the payload too.
    (tmp_path / "lib" / f"{quoted}.lig").write_text(
        f"{{@ WEDGE: {p.replace('}', ')')} }}\nWEDGE :- BOX WIDTH 1, HEIGHT 2, DEPTH 1\nPRINT '{quoted}'\n", newline=""
    )
    name = f"{p}.lig"  # the program's own file name
    (tmp_path / name).write_text(program(p), newline="")
    results = every_command(tmp_path, name)
    if brk == "\u0085":
        # A C1 control character is not LIG text: refused where it first appears.
        assert [r[0] for r in results] == [1, 1, 1]
        # (The file name in front may be shown escaped.)
        assert re.search(r"#\.lig:1:\d+: error: the file holds a control character \(U\+0085\)", results[0][2])
        return
    # Otherwise the payload program is an ordinary program: every command
    # succeeds, so lowering and running were exercised, not just a refusal.
    assert [r[0] for r in results] == [0, 0, 0, 0], results
    assert quoted in results[1][1]  # PRINT (which writes while rendering) shows the quoted word as written
    assert (tmp_path / "out2" / "scene1" / "00000.png").exists()


def test_a_file_name_with_u0085_compiles_to_a_module_that_runs(tmp_path):
    # The test above cannot take U+0085 through its file name alone: the text refuses it first.
    name = f"a\u0085{CODE}\u0085#.lig"
    (tmp_path / name).write_text(
        "INITIALIZE SCENE 1\nBACKGROUND BOX WIDTH 1, HEIGHT 1, DEPTH 1\nSTARTSCENE LENGTH 1\nENDSCENE\nSHOOTSCENES\n"
    )
    results = every_command(tmp_path, name)
    assert [r[0] for r in results] == [0, 0, 0, 0], results
    assert (tmp_path / "out2" / "scene1" / "00000.png").exists()


# ------------------------------------------------------------- cache

CACHE_PROGRAM = """\
LOAD CUBE FROM 'lib.lig'
INITIALIZE SCENE 1
BACKGROUND CUBE
STARTSCENE LENGTH 1
ENDSCENE
SHOOTSCENES
"""


@pytest.fixture
def cached(tmp_path, monkeypatch):
    """A program, its library, an empty private cache folder and the library's entry name."""
    (tmp_path / "lib.lig").write_text(LIB)
    (tmp_path / "p.lig").write_text(CACHE_PROGRAM)
    cache = tmp_path / "cache"
    monkeypatch.setenv("LIGANIMATE_CACHE", str(cache))
    library.forget()
    path = os.path.realpath(tmp_path / "lib.lig")
    entry = library_cache.entry_name(
        library.compiler_fingerprint().encode(), path.encode(), b"lib.lig", (tmp_path / "lib.lig").read_bytes()
    )
    return tmp_path, cache, entry


def forged(folder) -> dict:
    """The library's real cache object with code that creates MARKER put in front of its module."""
    old = os.environ["LIGANIMATE_CACHE"]
    os.environ["LIGANIMATE_CACHE"] = ""
    try:
        library.forget()
        lib = library.load("lib.lig", library.resolve("lib.lig", str(folder / "p.lig")))
    finally:
        os.environ["LIGANIMATE_CACHE"] = old
        library.forget()
    obj = library._to_json(lib)
    obj["python"] = CODE + "\n" + obj["python"]
    return obj


def runs_cleanly(folder, env) -> None:
    code, out, err = liganimate(
        "run", "p.lig", "--size", "32x24", "--quiet", "-o", "out", cwd=folder, env=env, timeout=60
    )
    assert code == 0, out + err
    assert "Traceback" not in err
    assert (folder / "out" / "scene1" / "00000.png").exists()
    no_marker(folder)


def test_control_a_signed_entry_is_what_runs(cached):
    # The harness can see execution: an entry signed with the folder's key is
    # trusted, code and all. Every planted entry below must fail where this succeeds.
    folder, cache, entry = cached
    library_cache.write(entry, forged(folder))
    code, _, err = liganimate("check", "p.lig", cwd=folder, env={"LIGANIMATE_CACHE": str(cache)}, timeout=60)
    assert code == 0, err
    assert (folder / "MARKER").exists()


class _Exec:
    def __reduce__(self):
        return (exec, (CODE,))


def plant_pickle(cache, entry, folder):
    (cache / entry).write_bytes(pickle.dumps((1, _Exec())))


def plant_bad_mac(cache, entry, folder):
    body = json.dumps(forged(folder)).encode()
    (cache / entry).write_bytes(library_cache.FORMAT + b"\n" + b"0" * 64 + b"\n" + body)


def plant_fifo(cache, entry, folder):
    os.mkfifo(cache / entry)


def plant_symlink(cache, entry, folder):
    # A correctly signed entry, but reached through a link: not followed.
    library_cache.write(entry, forged(folder))
    (cache / entry).rename(folder / "elsewhere.json")
    (cache / entry).symlink_to(folder / "elsewhere.json")


def plant_other_owner(cache, entry, folder):
    library_cache.write(entry, forged(folder))
    os.chown(cache / entry, 65534, 65534)


def plant_in_a_shared_folder(cache, entry, folder):
    library_cache.write(entry, forged(folder))
    cache.chmod(0o777)


def plant_readable_key(cache, entry, folder):
    library_cache.write(entry, forged(folder))
    (cache / library_cache.KEY_FILE).chmod(0o644)


@pytest.mark.parametrize(
    "plant",
    [
        plant_pickle,
        plant_bad_mac,
        plant_fifo,
        plant_symlink,
        plant_other_owner,
        plant_in_a_shared_folder,
        plant_readable_key,
    ],
    ids=lambda f: f.__name__[6:],
)
def test_a_planted_entry_never_runs_nor_hangs(cached, plant):
    folder, cache, entry = cached
    if plant is plant_other_owner and os.geteuid() != 0:
        pytest.skip("giving a file to another user needs root (chown)")
    library_cache.write("warm.json", {})  # the folder and its key exist, as after any earlier run
    plant(cache, entry, folder)
    runs_cleanly(folder, {"LIGANIMATE_CACHE": str(cache)})


def test_a_shared_or_linked_cache_folder_is_not_used_and_says_so(tmp_path):
    shared = tmp_path / "shared"
    shared.mkdir(mode=0o777)
    shared.chmod(0o777)
    (tmp_path / "lib.lig").write_text(LIB)
    (tmp_path / "p.lig").write_text(CACHE_PROGRAM)
    code, _, err = liganimate("check", "p.lig", cwd=tmp_path, env={"LIGANIMATE_CACHE": str(shared)})
    assert code == 0, err
    assert "warning: not using the library cache" in err and "other users may write in it" in err
    assert os.listdir(shared) == []
    (tmp_path / "link").symlink_to(tmp_path / "private")
    (tmp_path / "private").mkdir(mode=0o700)
    code, _, err = liganimate("check", "p.lig", cwd=tmp_path, env={"LIGANIMATE_CACHE": str(tmp_path / "link")})
    assert code == 0 and "symbolic link" in err
    assert os.listdir(tmp_path / "private") == []


def test_cache_files_are_private_and_hold_no_pickle(cached):
    folder, cache, entry = cached
    compile_file(str(folder / "p.lig"))
    assert stat.S_IMODE(cache.stat().st_mode) == 0o700
    for f in cache.iterdir():
        assert stat.S_IMODE(f.stat().st_mode) == 0o600, f
    data = (cache / entry).read_bytes()
    assert data.startswith(library_cache.FORMAT + b"\n")
    json.loads(data.split(b"\n", 2)[2])
    assert sorted(f.name for f in cache.iterdir()) == sorted([entry, library_cache.KEY_FILE])


def test_an_entry_moved_to_another_name_is_a_miss(cached):
    _, cache, _ = cached
    library_cache.write("a.json", {"x": 1})
    assert library_cache.read("a.json") == {"x": 1}
    (cache / "a.json").rename(cache / "b.json")
    assert library_cache.read("b.json") is None


def test_an_older_folder_is_made_private(cached):
    _, cache, _ = cached
    cache.mkdir(mode=0o755)
    cache.chmod(0o755)
    library_cache.write("a.json", {"x": 1})
    assert stat.S_IMODE(cache.stat().st_mode) == 0o700
    assert library_cache.read("a.json") == {"x": 1}


def test_a_library_survives_the_json_round_trip():
    lib = library.load("humanoid", library.resolve("humanoid", "x.lig"))
    assert lib.signatures or lib.types
    assert library._from_json(json.loads(json.dumps(library._to_json(lib)))) == lib


# ------------------------------------------------------------- LOAD of foreign files

SECRET = "root:x:0:0:SECRET-7f3a9:/root:/bin/bash"


def test_load_never_shows_a_foreign_file(tmp_path):
    (tmp_path / "secret.lig").write_text(SECRET + "\n")
    (tmp_path / "secret.txt").write_text(SECRET + "\n")
    (tmp_path / "words.lig").write_text("SECRET-7f3a9 is here\n")
    (tmp_path / "binary.lig").write_bytes(b"X = 1\n" + SECRET.encode() + b"\x00\x1b[2J\n")
    (tmp_path / "latin1.lig").write_bytes(SECRET.encode() + b"\xb0\n")
    (tmp_path / "c1.lig").write_text(SECRET + "\u009b\n")
    os.mkfifo(tmp_path / "pipe.lig")
    (tmp_path / "folder.lig").mkdir()
    (tmp_path / "link.lig").symlink_to(tmp_path / "secret.txt")
    (tmp_path / "env.lig").symlink_to("/proc/self/environ")
    (tmp_path / "sub").mkdir()
    loads = {  # LOAD string -> what the diagnostic at its line must say (None: only that there is one)
        "../secret.lig": "the library '../secret.lig' has errors (shown above)",
        "../words.lig": "the library '../words.lig' has errors (shown above)",
        "../secret.txt": "cannot be read: a LOAD reads only files whose names end in .lig",
        "../secret": "cannot be read: a LOAD reads only files whose names end in .lig",
        "../link.lig": "cannot be read: a LOAD reads only files whose names end in .lig",
        "../env.lig": "cannot be read: a LOAD reads only files whose names end in .lig",
        "/proc/self/environ": "cannot be read: a LOAD reads only files whose names end in .lig",
        os.path.relpath("/etc/passwd", tmp_path / "sub"): "cannot be read: a LOAD reads only files",
        "../binary.lig": "cannot be read: not LIG text (a control character at line 2, column 40)",
        "../c1.lig": "cannot be read: not LIG text (a control character at line 1, column 40)",
        "../latin1.lig": "cannot be read: not UTF-8 text (a bad byte at line 1, column 40)",
        "../pipe.lig": "cannot be read: not an ordinary file but a named pipe",
        "../folder.lig": "cannot be read: not an ordinary file but a folder",
    }
    (tmp_path / "sub" / "p.lig").write_text("".join(f"LOAD '{n}'\n" for n in loads))
    code, out, err = liganimate(
        "check", "p.lig", cwd=tmp_path / "sub", env={"LIG_ENV_SECRET": "ENV-SECRET-51c2"}, timeout=60
    )
    assert code == 1
    for line, (name, said) in enumerate(loads.items(), start=1):
        assert f"p.lig:{line}:6: error: " in err, (name, err)
        assert said in err, (name, err)
    for secret in ("SECRET-7f3a9", "ENV-SECRET-51c2", "root:", "\x1b"):
        assert secret not in out + err, secret
    assert "Traceback" not in err
    # A .lig file that does not parse is reported by position only.
    assert "../secret.lig:1:5: error: the library does not parse as LIG here" in err


def test_a_library_that_parses_is_lig_text_and_is_shown(tmp_path):
    # The other side of the rule: a LIG library's own errors keep their line.
    (tmp_path / "lib.lig").write_text("X = UNDEFINED_THING + 1\n")
    (tmp_path / "p.lig").write_text("LOAD 'lib.lig'\n")
    code, _, err = liganimate("check", "p.lig", cwd=tmp_path)
    assert code == 1
    assert "lib.lig:1:5: error: UNDEFINED_THING is not defined" in err and "X = UNDEFINED_THING + 1" in err


def test_a_load_adds_lig_and_may_leave_the_program_folder(tmp_path):
    (tmp_path / "shared").mkdir()
    (tmp_path / "shared" / "lib.lig").write_text(LIB)
    (tmp_path / "prog").mkdir()
    (tmp_path / "prog" / "p.lig").write_text(f"LOAD '../shared/lib'\nLOAD CUBE FROM '{tmp_path}/shared/lib.lig'\n")
    compiled = compile_file(str(tmp_path / "prog" / "p.lig"))
    assert [lib.path for lib in compiled.checked.libraries] == [os.path.realpath(tmp_path / "shared" / "lib.lig")]


def test_a_large_library_is_refused_unread(tmp_path):
    with open(tmp_path / "big.lig", "wb") as fh:
        fh.truncate(65 * 1024 * 1024)  # sparse: costs no disk
    (tmp_path / "p.lig").write_text("LOAD 'big.lig'\n")
    with pytest.raises(LigDiagnostics) as info:
        compile_file(str(tmp_path / "p.lig"))
    (d,) = info.value.diagnostics
    assert d.message == "the library 'big.lig' cannot be read: larger than 64 MB, the most a LIG source may hold"


# ------------------------------------------------------------- the program file itself


def test_a_program_file_that_is_not_a_file_is_one_line(tmp_path):
    os.mkfifo(tmp_path / "pipe.lig")
    (tmp_path / "folder.lig").mkdir()
    for name, kind in (("pipe.lig", "a named pipe"), ("folder.lig", "a folder")):
        code, _, err = liganimate("check", name, cwd=tmp_path, timeout=60)
        assert code == 1
        assert err == f"liganimate: error: not an ordinary file but {kind}: {name}\n"


def test_a_binary_program_file_is_refused_at_its_first_control_character(tmp_path):
    (tmp_path / "bin.lig").write_bytes(b"X = 1\nY = 2 \x1b[31mRED\x00\n")
    code, _, err = liganimate("check", "bin.lig", cwd=tmp_path)
    assert code == 1
    assert err.startswith("bin.lig:2:7: error: the file holds a control character (U+001B), so it is not LIG text\n")
    assert "RED" not in err and "\x1b" not in err
    (tmp_path / "c1.lig").write_text("X = 1 { \u0085 }\n")
    code, _, err = liganimate("check", "c1.lig", cwd=tmp_path)
    assert code == 1 and err.startswith("c1.lig:1:9: error: the file holds a control character (U+0085)")


# ------------------------------------------------------------- LOADs that fail before parsing


def test_a_library_that_fails_is_reported_even_when_the_program_then_fails_to_parse(tmp_path):
    (tmp_path / "bad.lig").write_text(
        "PRIMITIVE PRISM\n  REAL S\n  PRISM ::= 'PRISM' 'SIZE' S ;\n"
        "  DRAW POLY FROM (0, 0, 0) TO (S, 0, 0) TO (0, S, 0)\n  RETURN\nEND\nX = 1 +\n"
    )
    (tmp_path / "p.lig").write_text("LOAD 'bad.lig'\nG :- PRISM SIZE 3\n")
    with pytest.raises(LigDiagnostics) as info:
        compile_file(str(tmp_path / "p.lig"))
    diags = info.value.diagnostics
    at_load = [d for d in diags if d.filename.endswith("p.lig") and (d.pos.line, d.pos.column) == (1, 6)]
    assert [d.message for d in at_load] == ["the library 'bad.lig' has errors (shown above)"]
    assert diags.index(at_load[0]) < len(diags) - 1, "the LOAD comes before the syntax error it causes"


def test_the_pre_parse_scan_swallows_only_load_failures(tmp_path, monkeypatch):
    (tmp_path / "lib.lig").write_text(LIB)
    (tmp_path / "p.lig").write_text("LOAD 'lib.lig'\n")
    real, calls = library.load, []

    def flaky(*args, **kw):
        calls.append(args)
        if len(calls) == 1:
            raise RuntimeError("a bug, not a LOAD failure")
        return real(*args, **kw)

    monkeypatch.setattr(library, "load", flaky)
    with pytest.raises(RuntimeError):
        compile_file(str(tmp_path / "p.lig"))
