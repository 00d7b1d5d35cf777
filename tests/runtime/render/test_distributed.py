"""Rendering on a Dask cluster (``--scheduler``): the same bytes as a local run, a killed worker survived.

The cluster is a :class:`distributed.LocalCluster` of two worker processes
(one thread each), started once for the module: its workers are real
processes, which can be killed.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import os
import pathlib
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

distributed = pytest.importorskip("distributed")  # the test extra installs it; a bare install has no Dask

from test_render import PROGRAM  # noqa: E402

from liganimate.compiler import load_program  # noqa: E402
from liganimate.runtime.errors import RenderError  # noqa: E402
from liganimate.runtime.render import distributed as dask_render  # noqa: E402
from liganimate.runtime.render.distributed import DaskExecutor  # noqa: E402

TICKS = 40
SIZE = (96, 72)


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0", silence_logs=40
    ) as c:
        yield c


def swing(folder: pathlib.Path, ticks: int = TICKS) -> pathlib.Path:
    path = folder / "swing.lig"
    path.write_text(PROGRAM.format(ticks=ticks, last=ticks - 1))
    return path


def render(folder: pathlib.Path, out: pathlib.Path, **options) -> None:
    program, _ = load_program(str(swing(folder)))
    program.render(str(out), size=SIZE, quiet=True, **options)


def files(folder: pathlib.Path) -> dict:
    """Every file under ``folder``, by relative path: its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def local_frames(tmp_path_factory) -> dict:
    folder = tmp_path_factory.mktemp("local")
    render(folder, folder / "frames")
    frames = files(folder / "frames")
    assert len(frames) == TICKS
    return frames


def liganimate(*args, cwd, env=None):
    return subprocess.run(
        [sys.executable, "-m", "liganimate", *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=300
    )


def test_frames_drawn_on_the_cluster_are_the_bytes_of_a_local_run(cluster, local_frames, tmp_path):
    out = tmp_path / "frames"
    render(tmp_path, out, executor=DaskExecutor(cluster))
    assert files(out) == local_frames  # also: no marker, lock or temporary file left behind


def test_the_command_renders_on_the_scheduler_given_by_option_or_environment(cluster, local_frames, tmp_path):
    # Relative output names, and the workers' current folder is not this one: they write nothing themselves.
    program = swing(tmp_path)
    size = f"{SIZE[0]}x{SIZE[1]}"
    address = cluster.scheduler_address
    by_option = liganimate(
        "run", program.name, "-o", "a", "--size", size, "--quiet", "--scheduler", address, cwd=tmp_path
    )
    assert by_option.returncode == 0, by_option.stderr
    env = dict(os.environ, LIGANIMATE_SCHEDULER=address)
    by_env = liganimate("run", program.name, "-o", "b", "--size", size, "--quiet", cwd=tmp_path, env=env)
    assert by_env.returncode == 0, by_env.stderr
    assert files(tmp_path / "a") == local_frames
    assert files(tmp_path / "b") == local_frames


def test_gif_and_mp4_made_on_the_cluster_are_the_bytes_of_a_local_run(cluster, tmp_path):
    pytest.importorskip("imageio_ffmpeg")  # the MP4's ffmpeg comes with the test extra
    movies = {}
    for where, options in (("local", {}), ("dask", {"executor": DaskExecutor(cluster)})):
        gif, mp4 = tmp_path / f"{where}.gif", tmp_path / f"{where}.mp4"
        program, _ = load_program(str(swing(tmp_path)))
        program.render(None, size=SIZE, quiet=True, gif=str(gif), mp4=str(mp4), **options)
        movies[where] = (gif.read_bytes(), mp4.read_bytes())
    assert movies["dask"] == movies["local"]
    assert movies["local"][0][:6] == b"GIF89a" and b"ftyp" in movies["local"][1][:16]


def _hook(flag: str):
    """A task that, the first time any worker runs it, draws half its images and waits to be killed.

    Made inside a function so that it is pickled by value: the workers
    need not import this test module.
    """

    def hook(fn, task):
        try:
            fd = os.open(flag, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return fn(task)
        fn(dataclasses.replace(task, images=task.images[: len(task.images) // 2]))
        os.write(fd, f"{os.getpid()}\n".encode())
        os.close(fd)
        time.sleep(60)  # the test kills this process meanwhile

    return hook


class HookedExecutor(DaskExecutor):
    """Every task goes through ``hook`` first."""

    def __init__(self, *args, hook, **kwargs):
        super().__init__(*args, **kwargs)
        self.hook = hook

    def submit(self, fn, *args):
        return super().submit(self.hook, fn, *args)


def test_a_worker_killed_mid_task_is_survived_and_every_frame_is_whole(cluster, local_frames, tmp_path):
    flag = tmp_path / "killed"
    killed = []

    def killer():
        # Kill the worker process from outside, as an operator or the OOM killer would.
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            try:
                pid = int(flag.read_text())
            except (OSError, ValueError):
                time.sleep(0.01)
                continue
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)
            return

    watcher = threading.Thread(target=killer, daemon=True)
    watcher.start()
    out = tmp_path / "frames"
    started = time.monotonic()
    render(tmp_path, out, executor=HookedExecutor(cluster, hook=_hook(str(flag))))
    watcher.join(5)
    assert killed, "no task reached the hook"
    assert time.monotonic() - started < 60  # the killed task was retried, not waited out
    with pytest.raises(ProcessLookupError):
        os.kill(killed[0], 0)
    assert files(out) == local_frames  # complete, in order, whole


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_unreachable_scheduler_is_one_sentence_and_nothing_is_written(tmp_path):
    program = swing(tmp_path)
    address = f"tcp://127.0.0.1:{_free_port()}"
    done = liganimate("run", str(program), "-o", "out", "--quiet", "--scheduler", address, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.startswith(
        f"liganimate: error: cannot reach the Dask scheduler at {address}: connection refused\n"
    )
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


def test_a_scheduler_that_accepts_and_stays_silent_is_refused_within_the_connect_timeout():
    # Issue 24: an endpoint that accepts and never answers kept the run waiting without end.
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(4)
        address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
        with pytest.raises(RenderError) as err:
            DaskExecutor(address, connect_timeout=0.5)
    assert err.value.message == (f"the Dask scheduler at {address} accepted the connection but did not answer in 0.5 s")
    assert err.value.hint


@pytest.mark.parametrize("address", ["foo://somewhere:8786", "tcp://host:port", "no.such.host.invalid:8786"])
def test_a_bad_scheduler_address_is_a_render_error(address):
    with pytest.raises(RenderError) as err:
        DaskExecutor(address, connect_timeout=2)
    assert address in err.value.message
    assert err.value.hint


def test_a_scheduler_without_workers_is_a_render_error():
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as empty:
        # It gives up after the wait it was given (the message says which), not the default.
        with pytest.raises(RenderError, match=r"has no workers \(waited 0\.5 s\)"):
            DaskExecutor(empty, worker_wait=0.5)


def _gated_writer(folder: str):
    """A task that marks its start, waits until the test opens the gate, then marks its end."""

    def task(i):
        base = pathlib.Path(folder)
        (base / f"{i}.started").write_text("")
        deadline = time.monotonic() + 120  # only a guard against a test that never opens the gate
        while not (base / "open").exists():
            if time.monotonic() > deadline:
                raise RuntimeError("the gate was never opened")
            time.sleep(0.01)
        (base / f"{i}.done").write_text("")
        return i

    return task


def test_shutdown_drops_tasks_not_started_and_waits_for_those_running(cluster, tmp_path):
    ex = DaskExecutor(cluster)
    task = _gated_writer(str(tmp_path))
    futures = [ex.submit(task, i) for i in range(12)]

    def marks(kind):
        return {int(p.name.split(".")[0]) for p in tmp_path.glob(f"*.{kind}")}

    # Both workers' threads hold a task at the gate, and the scheduler knows them as running.
    _wait_for(lambda: len(marks("started")) == 2 and dask_render._processing(ex.client))
    closing = threading.Thread(target=ex.shutdown, kwargs={"wait": True, "cancel_futures": True})
    closing.start()
    # Shutdown drops the queued tasks first (their futures end, cancelled); only then is the gate opened,
    # so no dropped task can have started.
    _wait_for(lambda: any(f.done() for f in futures))
    (tmp_path / "open").write_text("")
    closing.join(timeout=120)
    assert not closing.is_alive()
    started, done = marks("started"), marks("done")
    assert 2 <= len(started) < 12
    assert done == started  # every task that ran had finished when shutdown returned
    for i, f in enumerate(futures):
        assert f.done()
        if i not in started:
            assert isinstance(f.exception(), cf.CancelledError), i
    with pytest.raises(RuntimeError):
        ex.submit(task, 99)


def test_a_task_error_reaches_the_caller_after_its_retries(cluster, tmp_path):
    count = tmp_path / "runs"

    def failing():
        with open(count, "a") as f:
            f.write("x")
        raise RenderError("no space left on device while writing out/00001.png")

    ex = DaskExecutor(cluster, retries=2)
    try:
        with pytest.raises(RenderError, match="no space left"):
            ex.submit(failing).result(timeout=60)
    finally:
        ex.shutdown()
    assert count.read_text() == "xxx"


def test_a_worker_process_sets_up_its_allocator_once_before_its_first_task(monkeypatch):
    calls = []
    monkeypatch.setattr(dask_render, "_keep_freed_memory", lambda: calls.append(os.getpid()))
    monkeypatch.setattr(dask_render, "_TUNED", [])
    assert dask_render._call(abs, -2) == 2
    assert dask_render._call(abs, -3) == 3
    assert calls == [os.getpid()]


class _Answers:
    """A client whose workers answer ``run`` with the given results (what a real cluster returns)."""

    def __init__(self, answers):
        self.answers = answers

    def run(self, fn, on_error):
        assert on_error == "return"
        return self.answers


def test_workers_without_liganimate_or_with_other_versions_are_refused_before_any_task():
    mine = dask_render._environment()
    dask_render._check_workers(_Answers({"tcp://w1:1": mine, "tcp://w2:1": [list(p) for p in mine]}))
    missing = Exception("ModuleNotFoundError(\"No module named 'liganimate'\")")
    with pytest.raises(RenderError, match=r"^the Dask worker at tcp://w2:1 cannot import liganimate"):
        dask_render._check_workers(_Answers({"tcp://w1:1": mine, "tcp://w2:1": missing}))
    older = tuple((name, "0.0.1") if name == "numpy" else (name, v) for name, v in mine)
    with pytest.raises(RenderError, match=r"^the Dask worker at tcp://w1:1 has numpy 0\.0\.1, this machine "):
        dask_render._check_workers(_Answers({"tcp://w1:1": older}))


# Loaded by the workers' Python at start-up (sitecustomize on PYTHONPATH): liganimate is not installed there.
_NO_LIGANIMATE = """\
import sys


class _Hide:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "liganimate":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, _Hide())
"""


def test_a_cluster_whose_workers_lack_liganimate_is_refused_in_words(tmp_path, monkeypatch):
    (tmp_path / "sitecustomize.py").write_text(_NO_LIGANIMATE)
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))  # read by the worker processes when they start
    with distributed.LocalCluster(
        n_workers=1, processes=True, threads_per_worker=1, dashboard_address=":0", silence_logs=50
    ) as bare:
        with pytest.raises(RenderError) as err:
            DaskExecutor(bare)
    assert err.value.message.endswith("cannot import liganimate; install the same liganimate on every worker")


def _wait_for(predicate, seconds: float = 60.0):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("timed out")


def test_a_scheduler_lost_mid_render_is_one_sentence_and_the_frames_before_are_whole(tmp_path, capfd):
    # A scheduler of its own, in a process that can be killed (a LocalCluster's lives in this one).
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = [sys.executable, "-m", "dask"]
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = subprocess.Popen([*dask, "scheduler", "--port", str(port), "--dashboard-address", ":0"], **quiet)
    worker = None
    try:
        _wait_for(lambda: _listening(port))
        worker = subprocess.Popen([*dask, "worker", address, "--nworkers", "1", "--nthreads", "1"], **quiet)
        flag = tmp_path / "drawing"

        def kill_scheduler():
            _wait_for(flag.exists, 120)
            scheduler.kill()

        killer = threading.Thread(target=kill_scheduler, daemon=True)
        killer.start()
        out = tmp_path / "frames"
        program, _ = load_program(str(swing(tmp_path, ticks=400)))
        executor = HookedExecutor(address, hook=_mark_then_draw(str(flag)), worker_wait=60)
        capfd.readouterr()
        with pytest.raises(RenderError) as err:
            program.render(str(out), size=SIZE, quiet=True, executor=executor)
        killer.join(5)
    finally:
        scheduler.kill()
        if worker is not None:
            worker.kill()
            worker.wait(30)
        scheduler.wait(30)
    assert err.value.message.startswith(f"the connection to the Dask scheduler at {address} was lost while drawing")
    assert "Traceback" not in capfd.readouterr().err  # Dask's reconnection attempts are not printed
    names = sorted(p.name for p in (out / "scene1").iterdir())
    assert names == [f"{i:05d}.png" for i in range(len(names))] and len(names) < 400  # whole, no gaps


def _listening(port: int) -> bool:
    with socket.socket() as s:
        return s.connect_ex(("127.0.0.1", port)) == 0


def _mark_then_draw(flag: str):
    """A task that says drawing has begun, then draws slowly enough for the render to be cut off midway."""

    def hook(fn, *args):
        time.sleep(0.05)
        with open(flag, "a") as f:
            f.write("x")
        return fn(*args)

    return hook


def test_dask_logging_is_silenced_while_the_executor_is_open_and_restored_after(cluster):
    import logging

    client_log = logging.getLogger("distributed.client")
    before = client_log.level
    ex = DaskExecutor(cluster)
    assert not client_log.isEnabledFor(logging.CRITICAL)
    ex.shutdown()
    assert client_log.level == before
    DaskExecutor(cluster, silence_logs=False).shutdown()
    assert client_log.level == before


# --------------------------------------------------------------------------
# Issue 24: every wait bounded, a task too


@pytest.fixture(scope="module")
def thread_cluster():
    """One in-process worker thread: a task that hangs there hangs as on any worker."""
    with distributed.LocalCluster(
        n_workers=1, processes=False, threads_per_worker=2, dashboard_address=":0", silence_logs=40
    ) as c:
        yield c


def _hang(gate: str, seconds: float) -> str:
    """A task that hangs until ``gate`` exists (or ``seconds`` pass), as a stuck worker would."""
    deadline = time.monotonic() + seconds
    while not os.path.exists(gate) and time.monotonic() < deadline:
        time.sleep(0.05)
    return "late"


def test_a_task_that_hangs_fails_after_the_task_timeout_in_one_sentence(thread_cluster, tmp_path):
    ex = DaskExecutor(thread_cluster, task_timeout=1.5)
    try:
        start = time.monotonic()
        hung = ex.submit(_hang, str(tmp_path / "gate"), 120)
        quick = ex.submit(abs, -4)
        assert quick.result(timeout=60) == 4  # the deadline is per task
        with pytest.raises(RenderError) as info:
            hung.result(timeout=60)
        assert time.monotonic() - start < 30
        assert info.value.message == (
            f"a task on the Dask cluster at {ex.address} did not answer in 1.5 s (a worker hangs, or the "
            "scheduler stopped answering); the frames written before are complete"
        )
        assert dask_render.TASK_TIMEOUT_ENV in info.value.hint
    finally:
        (tmp_path / "gate").write_text("")
        ex.shutdown(wait=False)


def test_the_task_timeout_comes_from_its_environment_variable(monkeypatch):
    monkeypatch.setenv(dask_render.TASK_TIMEOUT_ENV, "2.5")
    assert dask_render.task_timeout_from_env() == 2.5
    monkeypatch.delenv(dask_render.TASK_TIMEOUT_ENV)
    assert dask_render.task_timeout_from_env() == dask_render.TASK_TIMEOUT == 600
    for bad in ("0", "-1", "soon", "inf", "nan"):
        monkeypatch.setenv(dask_render.TASK_TIMEOUT_ENV, bad)
        with pytest.raises(RenderError, match=f"{dask_render.TASK_TIMEOUT_ENV}='{bad}' is not a number of seconds"):
            dask_render.task_timeout_from_env()


def test_a_render_whose_task_hangs_stops_with_one_sentence_and_whole_files(thread_cluster, tmp_path, monkeypatch):
    gate = tmp_path / "gate"
    real = dask_render._call

    def stuck(fn, *args):  # every drawing task hangs, as on a worker stuck in C code
        _hang(str(gate), 120)
        return real(fn, *args)

    monkeypatch.setattr(dask_render, "_call", stuck)
    ex = DaskExecutor(thread_cluster, task_timeout=1.0, close_wait=1.0)
    try:
        with pytest.raises(RenderError, match="did not answer in 1 s"):
            render(tmp_path, tmp_path / "frames", executor=ex)
    finally:
        gate.write_text("")
        ex.shutdown(wait=False)
    assert not [p for p in tmp_path.rglob("*") if p.name.endswith(".tmp")]


def test_ctrl_c_while_waiting_on_the_scheduler_stops_at_once_without_a_traceback(tmp_path):
    """A real scheduler without workers: the run waits for one; Ctrl-C ends it with status 130 and one sentence."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    scheduler = subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port)]
        + ["--dashboard-address", ":0"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        _wait_for(lambda: _listening(port))
        swing(tmp_path)
        run = subprocess.Popen(
            [sys.executable, "-m", "liganimate", "run", "swing.lig", "--size", "16x12", "-o", "out"]
            + ["--scheduler", f"tcp://127.0.0.1:{port}"],
            cwd=tmp_path,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
            # A background shell's children inherit SIGINT ignored; Ctrl-C at a terminal is not.
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
        _wait_for(lambda: _connected_to(run.pid, port))  # the run has reached the scheduler and waits for a worker
        os.killpg(run.pid, signal.SIGINT)
        stopped = time.monotonic()
        _, err = run.communicate(timeout=60)
        assert time.monotonic() - stopped < 5
        assert run.returncode == 130
        assert err == "\nliganimate: interrupted; every file already written is complete\n"
        assert not (tmp_path / "out").exists() or not list((tmp_path / "out").rglob("*.png"))
    finally:
        scheduler.kill()
        scheduler.wait()


def _listening(port: int) -> bool:
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
    except OSError:
        return False
    return True


def _connected_to(pid: int, port: int) -> bool:
    """Whether process ``pid`` holds an established TCP connection to ``port`` on this machine (Linux /proc)."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            target = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    with open("/proc/net/tcp") as f:
        rows = [line.split() for line in f.readlines()[1:]]
    return any(r[9] in inodes and int(r[2].split(":")[1], 16) == port and r[3] == "01" for r in rows)
