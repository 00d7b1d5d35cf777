"""Fuzzing at scale: generated programs must run or be diagnosed, never end in an internal error.

Runs the generators of tests/fuzzgen.py -- grammar expansion of
lang/lig.lark, extreme-number templates, cross-file splices of the
examples and standard libraries, grammar programs with extreme numbers
("wild"), deep and long constructs around and past the nesting limits
("deep"), non-ASCII characters put into real programs ("unicode"), and
with ``--generators mutate`` the line and token mutations of
benchmarks/fuzz_compile.py -- in a pool of worker processes. Each case is
compiled and checked, and every ``--render-every``-th case (default 10th)
also rendered at 16x12, exactly as tests/fuzzrun.py does it, and sorted
into ok, diagnosed, error, slow, or one of the failures:

* ``crash``: what the CLI would report as an internal error;
* ``baddiag``: a diagnostic without a position or with Python text in it;
* ``disagree``: ``check`` passed but the render failed;
* ``leak``: a Python RuntimeWarning reached stderr;
* ``hang``: the worker spent ``--hang`` CPU seconds (default 20) on a case without answering, and was killed;
* ``died``: the worker process died (a signal, the kernel's OOM killer).

Failures are grouped by kind and site (exception type and innermost
liganimate frame); the shortest program of each group is minimised
(delta debugging over lines, then tokens) and printed. Every case is
reproducible: case ``i`` of generator ``g`` uses ``random.Random(f"{seed}-{g}-{i}")``.

Usage::

    python benchmarks/fuzz.py --quick              # under a minute
    python benchmarks/fuzz.py                      # 100,000 cases
    python benchmarks/fuzz.py --cases 3000 --findings findings.md

The last line printed is one JSON object: cases (all checked), rendered,
outcomes, internal_errors (crashes), failures (every failure kind), hangs,
distinct failure sites, seconds, rate, peak_rss_mb (the largest resident
set of any worker), over_1gb and the options.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import json
import multiprocessing
import os
import random
import resource
import shutil
import signal
import sys
import tempfile
import time
from multiprocessing.connection import wait

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "tests"))

import fuzzgen  # noqa: E402 - found through the sys.path line above
import fuzzrun  # noqa: E402

WORKER_FAILURES = ("hang", "died")
ALL_OUTCOMES = fuzzrun.OUTCOMES + WORKER_FAILURES


@functools.lru_cache(maxsize=1)
def _mutations():
    """benchmarks/fuzz_compile.py (its line and token mutations) and the examples it mutates."""
    spec = importlib.util.spec_from_file_location("liganimate_fuzz_compile", os.path.join(HERE, "fuzz_compile.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod, mod.example_sources()


def generate(generator: str, seed: str) -> str:
    """The program of one case."""
    rng = random.Random(seed)
    if generator == "mutate":
        mod, sources = _mutations()
        return mod.random_case(rng, sources)[1]
    return fuzzgen.GENERATORS[generator](rng)


def _rss_mb() -> float:
    """This process's peak resident set, in MB (ru_maxrss is in kB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _cpu_seconds(pid: int) -> float:
    """User and system CPU seconds of process ``pid`` (Linux /proc; 0 where it cannot be read)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return 0.0


def worker(conn, limit: float, memory: int) -> None:
    """Run the tasks the parent sends until it sends None."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides when to stop
    workdir = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"ligfuzz-worker-{os.getpid()}")
    os.makedirs(workdir, exist_ok=True)
    try:
        while True:
            task = conn.recv()
            if task is None:
                return
            if task[0] == "case":
                _, tid, generator, seed, render = task
                text = generate(generator, seed)
                out = fuzzrun.timed(text, limit=limit, memory=memory, workdir=workdir, render=render)
                keep = out.failed
                conn.send(
                    (tid, out.kind, out.site, out.detail, round(out.seconds, 4), _rss_mb(), text if keep else None)
                )
            else:  # ("minimise", tid, text, kind, site, budget)
                _, tid, text, kind, site, budget = task
                small = fuzzrun.minimise(text, fuzzrun.Outcome(kind, site=site), budget=budget, limit=limit)
                conn.send((tid, "minimised", site, "", 0.0, _rss_mb(), small))
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


class Pool:
    """Worker processes fed one task at a time, each task with a hard deadline."""

    def __init__(self, size: int, limit: float, memory: int):
        self.ctx = multiprocessing.get_context("fork")
        self.limit, self.memory = limit, memory
        self.workers: list = [self._start() for _ in range(size)]
        self.peak_rss = 0.0

    def _start(self):
        parent, child = self.ctx.Pipe()
        p = self.ctx.Process(target=worker, args=(child, self.limit, self.memory), daemon=True)
        p.start()
        child.close()
        return {"proc": p, "conn": parent, "task": None, "deadline": 0.0}

    def idle(self) -> list:
        """The workers without a task."""
        return [w for w in self.workers if w["task"] is None]

    def submit(self, w, task, hard: float) -> None:
        """Hand ``task`` to worker ``w``; it is killed if it spends ``hard`` CPU seconds on it without an answer.

        CPU, not wall time: on a shared machine (or under ``nice``) a case may
        wait for the processor far longer than it computes. A worker that
        has not answered in ten times ``hard`` of wall time is killed too.
        """
        w["task"] = task
        w["hard"] = hard
        w["deadline"] = time.monotonic() + hard
        w["cpu0"] = _cpu_seconds(w["proc"].pid)
        w["conn"].send(task)

    def results(self, timeout: float = 0.5):
        """Yield ``(task, result or (failure kind, detail))`` as tasks finish, die or time out."""
        busy = [w for w in self.workers if w["task"] is not None]
        if not busy:
            return
        ready = wait([w["conn"] for w in busy], timeout)
        now = time.monotonic()
        for i, w in enumerate(self.workers):
            if w["task"] is None:
                continue
            task = w["task"]
            if w["conn"] in ready:
                try:
                    result = w["conn"].recv()
                except (EOFError, OSError):
                    w["proc"].join(1)
                    code = w["proc"].exitcode
                    yield task, ("died", f"worker exit code {code}")
                    self._replace(i)
                    continue
                self.peak_rss = max(self.peak_rss, result[5])
                w["task"] = None
                yield task, result
            elif now > w["deadline"]:
                spent = _cpu_seconds(w["proc"].pid) - w["cpu0"]
                if spent < w["hard"] and now < w["deadline"] + 9 * w["hard"]:
                    w["deadline"] = now + (w["hard"] - spent)  # waited for the CPU: not a hang yet
                    continue
                yield task, ("hang", f"no answer after {spent:.0f} s of CPU; the worker was killed")
                self._replace(i, kill=True)

    def _replace(self, i: int, kill: bool = False) -> None:
        w = self.workers[i]
        if kill and w["proc"].is_alive():
            os.kill(w["proc"].pid, signal.SIGKILL)
        w["proc"].join(5)
        w["conn"].close()
        self.workers[i] = self._start()

    def close(self) -> None:
        """Stop every worker and take the largest resident set any of them reached."""
        for w in self.workers:
            try:
                if w["task"] is None:
                    w["conn"].send(None)
                elif w["proc"].is_alive():
                    os.kill(w["proc"].pid, signal.SIGKILL)
            except OSError:
                pass
        for w in self.workers:
            w["proc"].join(5)
        children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
        self.peak_rss = max(self.peak_rss, children)


def run(args) -> dict:
    """Run the cases; return counts per generator, failure groups, minimised programs, time and memory."""
    generators = args.generators.split(",")
    pool = Pool(args.workers, args.limit, args.memory << 20)
    hard = args.hang  # a worker that has not answered by then is killed: a hang
    counts = {g: dict.fromkeys(ALL_OUTCOMES, 0) for g in generators}
    groups: dict = {}  # (kind, site) -> {"count", "text", "detail", "generator", "seed"}
    start = time.monotonic()
    budget_end = start + args.budget
    next_case = 0
    rendered = 0
    done = 0
    last_report = start
    try:
        while done < args.cases:
            while next_case < args.cases and pool.idle() and time.monotonic() < budget_end:
                g = generators[next_case % len(generators)]
                seed = f"{args.seed}-{g}-{next_case}"
                render = next_case % args.render_every == 0
                rendered += render
                pool.submit(pool.idle()[0], ("case", next_case, g, seed, render), hard)
                next_case += 1
            if not any(w["task"] for w in pool.workers):
                break  # the time budget ran out
            for task, result in pool.results():
                _, _, g, seed, _ = task
                done += 1
                if result[0] in WORKER_FAILURES:
                    kind, detail = result
                    site, text, seconds = f"{kind} in a worker", generate(g, seed), hard
                else:
                    _, kind, site, detail, seconds, _, text = result
                counts[g][kind] += 1
                if kind in fuzzrun.FAILURES or kind in WORKER_FAILURES:
                    grp = groups.setdefault(
                        (kind, site), {"count": 0, "text": None, "detail": detail, "generator": g, "seed": seed}
                    )
                    grp["count"] += 1
                    if grp["text"] is None or len(text) < len(grp["text"]):
                        grp.update(text=text, detail=detail, generator=g, seed=seed)
            now = time.monotonic()
            if not args.quiet and now - last_report > 30:
                last_report = now
                failures = sum(g["count"] for g in groups.values())
                print(
                    f"  {done} cases, {failures} failures, {len(groups)} sites, {now - start:.0f} s",
                    file=sys.stderr,
                    flush=True,
                )
        seconds = time.monotonic() - start
        minimised = minimise_groups(pool, groups, args) if args.minimise else {}
    finally:
        pool.close()
    return {
        "counts": counts,
        "groups": groups,
        "minimised": minimised,
        "done": done,
        "rendered": rendered,
        "seconds": seconds,
        "peak_rss_mb": pool.peak_rss,
    }


def minimise_groups(pool: Pool, groups: dict, args) -> dict:
    """The minimised program of each failure group (the first ``args.minimise`` groups, largest first)."""
    order = sorted(groups, key=lambda k: -groups[k]["count"])[: args.minimise]
    todo = [k for k in order if k[0] in fuzzrun.FAILURES]  # hangs and deaths are not re-run
    out: dict = {}
    hard = args.minimise_budget + args.limit * 3 + 30
    while todo or any(w["task"] for w in pool.workers):
        while todo and pool.idle():
            key = todo.pop(0)
            grp = groups[key]
            pool.submit(pool.idle()[0], ("minimise", key, grp["text"], key[0], key[1], args.minimise_budget), hard)
        for task, result in pool.results():
            key = task[1]
            out[key] = result[6] if result[0] not in WORKER_FAILURES else groups[key]["text"]
    return out


def report(res: dict, args) -> dict:
    """Print the table and the failure groups; return the summary for the final JSON line."""
    counts, groups = res["counts"], res["groups"]
    total = dict.fromkeys(ALL_OUTCOMES, 0)
    for per in counts.values():
        for k, v in per.items():
            total[k] += v
    print(f"{'generator':<10}" + "".join(f"{k:>10}" for k in ALL_OUTCOMES))
    for g, per in counts.items():
        print(f"{g:<10}" + "".join(f"{per[k]:>10}" for k in ALL_OUTCOMES))
    for (kind, site), grp in sorted(groups.items(), key=lambda kv: -kv[1]["count"]):
        print(f"{grp['count']:7d}  {kind:<9} {site}  [{grp['generator']}]  {grp['detail'][:100]}")
    if args.show:
        for key, small in list(res["minimised"].items())[: args.show]:
            print(f"--- {key[0]}: {key[1]} ---\n{small.rstrip()}", file=sys.stderr)
    if args.findings:
        write_findings(args.findings, res, total, args)
    failures = sum(total[k] for k in fuzzrun.FAILURES + WORKER_FAILURES)
    done, seconds = res["done"], res["seconds"]
    summary = {
        "cases": done,
        "checked": done,
        "rendered": res["rendered"],
        "outcomes": total,
        "internal_errors": total["crash"],
        "failures": failures,
        "distinct_sites": len(groups),
        "seconds": round(seconds, 1),
        "rate": round(done / seconds, 1) if seconds else None,
        "peak_rss_mb": round(res["peak_rss_mb"], 1),
        "over_1gb": res["peak_rss_mb"] > 1024,
        "hangs": total["hang"],
        "hang_budget_s": args.hang,
        "workers": args.workers,
        "generators": args.generators,
        "seed": args.seed,
        "quick": args.quick,
    }
    return summary


def write_findings(path: str, res: dict, total: dict, args) -> None:
    """A markdown list of the distinct failure sites with a minimal program each."""
    lines = [
        "# Fuzz findings",
        "",
        (
            f"`python benchmarks/fuzz.py --cases {args.cases} --seed {args.seed} --generators {args.generators}`: "
            f"{res['done']} cases in {res['seconds']:.0f} s; outcomes {json.dumps(total)}; "
            f"peak RSS {res['peak_rss_mb']:.0f} MB."
        ),
        "",
        (
            "Each entry: outcome, site (exception and innermost liganimate frame), cases that hit it, "
            "the generator and seed of its shortest case, and the minimised program."
        ),
        "",
    ]
    groups = res["groups"]
    for n, ((kind, site), grp) in enumerate(sorted(groups.items(), key=lambda kv: -kv[1]["count"]), 1):
        small = res["minimised"].get((kind, site), grp["text"])
        lines += [
            f"## {n}. {kind}: {site}",
            "",
            f"{grp['count']} cases; shortest from `{grp['generator']}` seed `{grp['seed']}`.",
            f"Message: `{grp['detail'][:300]}`",
            "",
            "```",
            small.rstrip() if len(small) < 4000 else small[:4000] + "\n... (cut)",
            "```",
            "",
        ]
    if not groups:
        lines.append("No failures.")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="a run of under a minute")
    parser.add_argument("--cases", type=int, help="cases to run (default 100000, or 2000 with --quick)")
    parser.add_argument(
        "--budget", type=float, help="stop starting cases after this many seconds (default none, or 35 with --quick)"
    )
    parser.add_argument("--seed", type=int, default=1986)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument(
        "--generators",
        default="grammar,numbers,splice,wild,deep,unicode",
        help="comma-separated: grammar, numbers, splice, wild, deep, unicode, mutate",
    )
    parser.add_argument("--limit", type=float, default=2.0, help="seconds per case before it counts as slow")
    parser.add_argument(
        "--hang",
        type=float,
        default=20.0,
        help="CPU seconds after which a case that has not answered is a hang (killed)",
    )
    parser.add_argument(
        "--render-every",
        type=int,
        default=10,
        metavar="N",
        help="render every Nth case after its check (default 10: 100,000 checked, 10,000 run)",
    )
    parser.add_argument("--memory", type=int, default=1024, help="MB of address space a case may add")
    parser.add_argument("--minimise", type=int, help="failure groups to minimise (default all, 3 with --quick)")
    parser.add_argument("--minimise-budget", type=float, help="seconds per minimisation (default 30, 4 with --quick)")
    parser.add_argument("--show", type=int, default=5, help="print this many minimised programs")
    parser.add_argument("--findings", metavar="FILE.md", help="write the failure sites and minimal programs here")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    args = parser.parse_args(argv)
    for name in args.generators.split(","):
        if name not in fuzzgen.GENERATORS and name != "mutate":
            parser.error(f"unknown generator {name!r}")
    args.cases = args.cases or (2000 if args.quick else 100_000)
    args.budget = args.budget if args.budget is not None else (35.0 if args.quick else float("inf"))
    args.minimise = args.minimise if args.minimise is not None else (3 if args.quick else 10_000)
    args.minimise_budget = args.minimise_budget or (4.0 if args.quick else 30.0)
    # One thread per worker for numpy's BLAS: the workers are the parallelism.
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    # Compiled libraries go to a folder of this run, not the user's cache.
    cache = tempfile.mkdtemp(prefix="ligfuzz-cache-")
    os.environ["LIGANIMATE_CACHE"] = cache
    try:
        res = run(args)
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    print(json.dumps(report(res, args)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
