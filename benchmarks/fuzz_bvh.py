"""Fuzzing BVH import: every file imports into a library LOAD takes, or is refused at a BVH line.

Each case is a BVH file: a generated skeleton (a chain of 1 to 3,000
joints, or a branching tree, with random channel orders and frames) or,
when the test captures are in tests/.cache, a real capture cut to a few
frames; then one to three mutations: a number replaced by a boundary value
(1E308, NaN, 1E12 and just past it, 1E9 degrees, huge integers...), a line
deleted, doubled or swapped, the file cut at any byte, a brace or keyword
dropped, a count changed, a non-ASCII character put in, CRLF line endings.

A case runs as ``liganimate import`` does (``read_bvh``, then
``import_library``), and its library is then compiled and executed as
``LOAD`` would. It is sorted into:

* ``ok``: imported, and the library loads;
* ``diagnosed``: refused with diagnostics, each at a line and column of the BVH file;
* ``crash``: any other exception (what the command line calls an internal error);
* ``baddiag``: a diagnostic without a position, or not in the BVH file;
* ``unloadable``: imported, but the library it wrote is refused by LOAD;
* ``leak``: a Python warning (numpy overflow...) was raised;
* ``slow`` / ``hang``: over the time limit / no answer within ``--hang`` seconds.

Usage::

    python benchmarks/fuzz_bvh.py --quick          # under a minute
    python benchmarks/fuzz_bvh.py                  # 10,000 files

The last line printed is one JSON object: cases, outcomes, internal_errors,
failures, the failure sites with a short example each, seconds, rate and
peak_rss_mb.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import random
import re
import resource
import shutil
import sys
import tempfile
import time
import warnings

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests"))

import fuzzrun  # noqa: E402 - found through the sys.path line above

OUTCOMES = ("ok", "diagnosed", "slow", "crash", "baddiag", "unloadable", "leak", "hang")
FAILURES = ("crash", "baddiag", "unloadable", "leak", "hang")

CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")
SIZES = (1, 2, 5, 20, 99, 100, 101, 500, 1000, 3000)
BOUNDARY = (
    "1E308",
    "-1.5E308",
    "1E309",
    "nan",
    "inf",
    "-inf",
    "-0",
    "0",
    "5e-324",
    "1E12",
    "1000000000000.5",
    "-1E12",
    "999999999999",
    "1E9",
    "1000000001",
    "-1E9",
    "9223372036854775808",
    "1" * 400,
    "1e-300",
    "0x10",
    "1_000",
    "½",
    "١",
    "",
)
UNICODE = ("é", "Ж", "\u00a0", "\u200b", "\u202e", "\ufeff", "\x00", "\x1b[31m", "😀", "\t", "\r", "\x85")


def skeleton(rng: random.Random) -> str:
    """A generated BVH file: a chain or a tree, channels in random orders, 1 to 4 frames."""
    n = SIZES[rng.randrange(len(SIZES))]
    branch = rng.random() < 0.4
    lines = ["HIERARCHY", "ROOT Hips", "{", "  OFFSET 0 0 0"]
    root_channels = list(CHANNELS)
    rng.shuffle(root_channels)
    lines.append(f"  CHANNELS {len(root_channels)} " + " ".join(root_channels))
    counts = [len(root_channels)]
    depth = 1
    for i in range(n):
        if branch and depth > 1 and rng.random() < 0.3:
            lines.append("}")
            depth -= 1
        k = rng.choice((0, 3, 3, 3, 6))
        chans = rng.sample(CHANNELS[3:], 3) if k == 3 else rng.sample(CHANNELS, k)
        off = " ".join(f"{rng.uniform(-2, 2):.4f}" for _ in range(3))
        lines += [f"JOINT J{i}", "{", f"  OFFSET {off}", f"  CHANNELS {k} " + " ".join(chans)]
        counts.append(k)
        depth += 1
    lines += ["End Site", "{", "  OFFSET 0 1 0", "}"]
    lines += ["}"] * depth
    frames = 1 + rng.randrange(4)
    lines += ["MOTION", f"Frames: {frames}", "Frame Time: 0.0333333"]
    total = sum(counts)
    for _ in range(frames):
        lines.append(" ".join(f"{rng.uniform(-90, 90):.3f}" for _ in range(total)))
    return "\n".join(lines) + "\n"


_REAL: list = []


def real_captures() -> list:
    """The test captures' texts, cut to their first 4 frames (empty when they are not downloaded)."""
    if _REAL:
        return _REAL[0]
    texts = []
    cache = os.path.join(ROOT, "tests", ".cache", "captures")
    for folder, _, names in os.walk(cache):
        for name in sorted(names):
            if name.endswith(".bvh"):
                with open(os.path.join(folder, name), encoding="utf-8", errors="replace") as fh:
                    text = fh.read()
                head, _, motion = text.partition("MOTION")
                rows = motion.strip().splitlines()
                if len(rows) > 2:
                    texts.append(f"{head}MOTION\nFrames: 4\n{rows[1]}\n" + "\n".join(rows[2:6]) + "\n")
    _REAL.append(texts)
    return texts


def mutate(rng: random.Random, text: str) -> str:
    """One mutation of a BVH text."""
    lines = text.split("\n")
    r = rng.random()
    i = rng.randrange(len(lines))
    if r < 0.35:  # a number becomes a boundary value
        tokens = lines[i].split(" ")
        spots = [k for k, t in enumerate(tokens) if t.lstrip("-").replace(".", "", 1).isdigit()]
        if spots:
            tokens[rng.choice(spots)] = BOUNDARY[rng.randrange(len(BOUNDARY))]
            lines[i] = " ".join(tokens)
    elif r < 0.45:
        del lines[i]
    elif r < 0.52:
        lines.insert(i, lines[i])
    elif r < 0.58:
        j = rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
    elif r < 0.66:  # cut at any byte
        return text[: rng.randrange(len(text) + 1)]
    elif r < 0.74:  # a structural word dropped or changed
        words = ("{", "}", "JOINT", "End", "Site", "OFFSET", "CHANNELS", "MOTION", "Frames:", "Frame", "ROOT")
        lines[i] = lines[i].replace(rng.choice(words), rng.choice(("", "joint", "}", "{", "Xrotation")), 1)
    elif r < 0.82:  # a count changed
        for word in ("CHANNELS", "Frames:"):
            if word in lines[i]:
                head, _, rest = lines[i].partition(word)
                parts = rest.split()
                if parts:
                    # An earlier mutation may have left any text there (a value, a word): count on from digits only.
                    after = str(int(parts[0]) + 1) if parts[0].isdigit() else "1"
                    parts[0] = rng.choice(("0", "-1", "7", "99999999999", "2.5", after))
                lines[i] = head + word + " " + " ".join(parts)
    elif r < 0.94:
        at = rng.randrange(len(lines[i]) + 1)
        lines[i] = lines[i][:at] + UNICODE[rng.randrange(len(UNICODE))] + lines[i][at:]
    else:
        return text.replace("\n", "\r\n")
    return "\n".join(lines)


def generate(seed: str) -> str:
    """The BVH text of one case."""
    rng = random.Random(seed)
    real = real_captures()
    text = real[rng.randrange(len(real))] if real and rng.random() < 0.3 else skeleton(rng)
    if rng.random() < 0.9:
        for _ in range(1 + rng.randrange(3)):
            text = mutate(rng, text)
    return text


def _positioned(diags, path: str) -> str | None:
    """Why these diagnostics are not each at a line and column of the BVH file, or None."""
    if not diags:
        return "no diagnostic"
    for d in diags:
        if d.filename != path or d.pos.line < 1 or d.pos.column < 1:
            return f"not at a line of the BVH file: {d.filename}:{d.pos.line}:{d.pos.column}: {d.message}"
        words = re.sub(r"'[^']*'", "''", d.message + " " + (d.hint or ""))  # the file's own tokens may be quoted
        if "\n" in d.message or fuzzrun._PYTHON_TEXT.search(words):
            return f"Python text in the sentence: {d.message!r}"
    return None


def run_case(seed: str, limit: float, workdir: str) -> tuple:
    """``(outcome, site, detail, seconds)`` of one case, run as ``liganimate import`` and then LOAD run it."""
    from liganimate.compiler import load_program
    from liganimate.lang.diagnostics import LigDiagnostics
    from liganimate.runtime import exchange as X

    text = generate(seed)
    path = os.path.join(workdir, "capture.bvh")
    with open(path, "w", encoding="utf-8", errors="surrogatepass", newline="") as fh:
        fh.write(text)
    start = time.process_time()
    stage = "import"
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with fuzzrun.time_limit(limit), fuzzrun.memory_limit(1 << 30):
                clip = X.read_bvh(path)
                lib, _ = X.import_library(clip, X.ImportOptions(model="CAPTURE_FIGURE", motion="CAPTURE"))
                stage = "load"
                lib_path = os.path.join(workdir, "capture.lig")
                with open(lib_path, "wb") as fh:
                    fh.write(lib)
                load_program(
                    text="LOAD CAPTURE_FIGURE, CAPTURE FROM 'capture.lig'\n", name=os.path.join(workdir, "use.lig")
                )
        if caught:
            w = caught[0]
            return "leak", f"{w.category.__name__} from {os.path.basename(w.filename)}", str(w.message)[:200], 0.0
        return "ok", "", "", time.process_time() - start
    except fuzzrun.Slow:
        return "slow", "", stage, time.process_time() - start
    except LigDiagnostics as exc:
        if stage == "load":
            return "unloadable", fuzzrun.site_of(exc), str(exc).splitlines()[0][:200], 0.0
        bad = _positioned(exc.diagnostics, path)
        if bad:
            return "baddiag", fuzzrun.site_of(exc), bad[:200], 0.0
        return "diagnosed", "", "", time.process_time() - start
    except Exception as exc:  # noqa: BLE001 - an internal error is the finding
        return "crash", fuzzrun.site_of(exc), f"{type(exc).__name__}: {str(exc)[:200]}", 0.0


def _work(job):
    seed, limit = job
    workdir = os.path.join(tempfile.gettempdir(), f"ligfuzz-bvh-{os.getpid()}")
    os.makedirs(workdir, exist_ok=True)
    try:
        out = run_case(seed, limit, workdir)
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return (seed, *out, rss)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a run of under a minute")
    parser.add_argument("--cases", type=int, help="files to fuzz (default 10000, or 400 with --quick)")
    parser.add_argument("--budget", type=float, help="stop starting cases after this many seconds (35 with --quick)")
    parser.add_argument("--seed", type=int, default=1986)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--limit", type=float, default=20.0, help="seconds of a case before it counts as slow")
    parser.add_argument("--hang", type=float, default=60.0, help="seconds without an answer that count as a hang")
    args = parser.parse_args(argv)
    cases = args.cases or (400 if args.quick else 10_000)
    budget = args.budget if args.budget is not None else (35.0 if args.quick else float("inf"))
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    cache = tempfile.mkdtemp(prefix="ligfuzz-cache-")
    os.environ["LIGANIMATE_CACHE"] = cache
    counts = dict.fromkeys(OUTCOMES, 0)
    sites: dict = {}
    peak = 0.0
    cpu = 0.0
    start = time.monotonic()
    done = 0
    ctx = multiprocessing.get_context("fork")
    pool = ctx.Pool(args.workers, maxtasksperchild=200)
    try:
        jobs = ((f"{args.seed}-bvh-{i}", args.limit) for i in range(cases))
        results = pool.imap_unordered(_work, jobs)  # chunksize 1: an iterator with next(timeout)
        while done < cases and time.monotonic() - start < budget:
            try:
                seed, kind, site, detail, seconds, rss = results.next(timeout=args.hang)
            except StopIteration:
                break
            except multiprocessing.TimeoutError:
                counts["hang"] += 1
                sites.setdefault(("hang", "a worker"), {"count": 0, "seed": "?", "detail": ""})["count"] += 1
                break
            done += 1
            cpu += seconds
            peak = max(peak, rss)
            counts[kind] += 1
            if kind in FAILURES:
                grp = sites.setdefault((kind, site), {"count": 0, "seed": seed, "detail": detail})
                grp["count"] += 1
    finally:
        pool.terminate()
        pool.join()
        shutil.rmtree(cache, ignore_errors=True)
    seconds = time.monotonic() - start
    print(f"{'outcome':<12}{'cases':>8}")
    for k in OUTCOMES:
        print(f"{k:<12}{counts[k]:>8}")
    for (kind, site), grp in sorted(sites.items(), key=lambda kv: -kv[1]["count"]):
        print(f"{grp['count']:7d}  {kind:<10} {site}  seed {grp['seed']}  {grp['detail'][:120]}")
    summary = {
        "cases": done,
        "outcomes": counts,
        "internal_errors": counts["crash"],
        "failures": sum(counts[k] for k in FAILURES),
        "sites": {f"{k}: {s}": g["seed"] for (k, s), g in sites.items()},
        "seconds": round(seconds, 1),
        "cpu_seconds_in_cases": round(cpu, 1),
        "rate": round(done / seconds, 1) if seconds else None,
        "peak_rss_mb": round(peak, 1),
        "workers": args.workers,
        "seed": args.seed,
        "quick": args.quick,
    }
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
