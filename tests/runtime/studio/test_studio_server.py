"""The studio's server without a browser: loopback only, its four paths, and 4xx for every malformed request."""

from __future__ import annotations

import http.client
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time

import pytest
from commands import liganimate
from studio_support import running_studio

from liganimate.runtime.errors import LigError
from liganimate.runtime.studio import MAX_BODY, studio_model


@pytest.fixture
def server(tmp_path, humanoid):
    with running_studio(humanoid, "HUMANOID", tmp_path / "saved.lig", seed=9) as (srv, _):
        yield srv


def _request(srv, method, path, body=None, headers=None):
    conn = http.client.HTTPConnection("127.0.0.1", srv.port, timeout=10)
    h = {"Host": f"127.0.0.1:{srv.port}"}
    if body is not None:
        h["Content-Type"] = "application/json"
    h.update(headers or {})
    conn.request(method, path, body=body, headers=h)
    r = conn.getresponse()
    data = r.read()
    conn.close()
    return r.status, r.getheader("Content-Type", ""), data


def _act(srv, **body):
    status, _, data = _request(srv, "POST", "/api/action", json.dumps(body))
    return status, json.loads(data)


def _raw(srv, payload: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", srv.port), timeout=10) as s:
        s.sendall(payload)
        chunks = []
        while True:
            try:
                b = s.recv(65536)
            except (ConnectionResetError, TimeoutError):
                break
            if not b:
                break
            chunks.append(b)
    return b"".join(chunks)


def _alive(srv) -> None:
    status, ctype, data = _request(srv, "GET", "/api/state")
    assert status == 200 and ctype.startswith("application/json")
    assert json.loads(data)["generation"] >= 1


def test_binds_loopback_only(server):
    assert server.server_address[0] == "127.0.0.1"
    assert server.port > 0
    assert server.url == f"http://127.0.0.1:{server.port}/"


def test_page_and_state(server):
    status, ctype, page = _request(server, "GET", "/")
    assert status == 200 and ctype.startswith("text/html")
    text = page.decode("utf-8")
    assert '<canvas id="current"' in text and "LigGL" in text
    assert not re.search(r"(src|href)\s*=\s*[\"']?(https?:)?//", text)
    status, _, data = _request(server, "GET", "/api/state")
    state = json.loads(data)
    assert status == 200 and state["seed"] == 9 and state["generation"] == 1
    assert len(state["angles"]) == 10 and len(state["levels"]) == 9


def test_choices_then_save(server, tmp_path):
    status, _, _ = _request(server, "GET", "/library.lig")
    assert status == 404
    status, state = _act(server, action="take", candidate=2, link=2)
    assert status == 200 and "R_THIGH" in state["message"]
    assert state["angles"][0][1] == state["angles"][3][1]  # joint index 1 (31) taken from candidate 3
    status, state = _act(server, action="save")
    assert status == 400 and "keep a pose" in state["error"]
    assert _act(server, action="keep")[1]["kept"] == 1
    assert _act(server, action="next", intensity=0.5, mode="twist")[1]["generation"] == 2
    assert _act(server, action="keep")[1]["kept"] == 2
    status, state = _act(server, action="save")
    assert status == 200 and state["saved"]
    saved = tmp_path / "saved.lig"
    assert saved.is_file() and "STARTMOTION POSES" in saved.read_text(encoding="utf-8")
    status, _, data = _request(server, "GET", "/library.lig")
    assert status == 200 and data == saved.read_bytes()
    assert _act(server, action="undo")[1]["kept"] == 1


@pytest.mark.parametrize(
    "path",
    [
        "/../../../etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "/..%2f..%2fetc%2fpasswd",
        "//etc/passwd",
        "/saved.lig",
        "/studio.js",
        "/gl.js",
        "/api",
        "/api/state/../../x",
        "/index.html/..",
        "/C:/Windows/win.ini",
    ],
)
def test_paths_outside_its_files_are_404(server, path):
    status, ctype, data = _request(server, "GET", path)
    assert status == 404 and ctype.startswith("application/json")
    assert b"root:" not in data
    _alive(server)


@pytest.mark.parametrize(
    "body, why",
    [
        ("{not json", "not JSON"),
        ('"take"', "JSON object"),
        ("[1, 2]", "JSON object"),
        (json.dumps({"action": "explode"}), "unknown action"),
        (json.dumps({"nothing": 1}), "unknown action"),
        (json.dumps({"action": "take", "candidate": 9, "link": 2}), "candidate"),
        (json.dumps({"action": "take", "candidate": "1", "link": 2}), "candidate"),
        (json.dumps({"action": "take", "candidate": 1, "link": 0}), "main link"),
        (json.dumps({"action": "take", "candidate": 1, "link": 10**9}), "link"),
        (json.dumps({"action": "freeze", "link": -1}), "link"),
        (json.dumps({"action": "seed", "seed": 2**40}), "seed"),
        (json.dumps({"action": "seed", "seed": 1.5}), "seed"),
        (json.dumps({"action": "next", "intensity": 7}), "intensity"),
        (json.dumps({"action": "next", "mode": "sideways"}), "mode"),
        ('{"action": "next", "intensity": NaN}', "NaN"),
        (b"\xff\xfe{}", "not JSON"),
        ("[" * 60_000, "not JSON"),  # issue 24: a RecursionError was a 500
    ],
)
def test_bad_requests_are_400_and_change_nothing(server, body, why):
    before = _request(server, "GET", "/api/state")[2]
    status, ctype, data = _request(server, "POST", "/api/action", body)
    assert status == 400, data
    assert ctype.startswith("application/json") and why in json.loads(data)["error"]
    assert b"Traceback" not in data
    assert _request(server, "GET", "/api/state")[2] == before


def test_oversized_and_unlengthed_bodies(server):
    status, _, _data = _request(server, "POST", "/api/action", "x" * (MAX_BODY + 1))
    assert status == 413
    reply = _raw(
        server,
        (
            f"POST /api/action HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
            "Content-Type: application/json\r\nContent-Length: 99999999999\r\n\r\n{"
        ).encode(),
    )
    assert reply.startswith(b"HTTP/1.1 413")
    reply = _raw(
        server,
        (
            f"POST /api/action HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
            "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n1\r\n{\r\n0\r\n\r\n"
        ).encode(),
    )
    assert reply.startswith(b"HTTP/1.1 411")
    reply = _raw(
        server,
        (
            f"POST /api/action HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\n"
            "Content-Type: application/json\r\nContent-Length: -5\r\n\r\n"
        ).encode(),
    )
    assert reply.startswith(b"HTTP/1.1 400")
    status, _, _ = _request(server, "POST", "/api/action", "{}", {"Content-Type": "text/plain"})
    assert status == 415
    _alive(server)


def test_other_methods_hosts_and_origins(server):
    for method in ("PUT", "DELETE", "PATCH", "OPTIONS", "TRACE", "BREW"):
        status, _, _ = _request(server, method, "/")
        assert status == 405, method
    status, _, _ = _request(server, "GET", "/api/state", headers={"Host": "evil.example:80"})
    assert status == 403
    status, _, _ = _request(
        server, "POST", "/api/action", json.dumps({"action": "keep"}), {"Origin": "http://evil.example"}
    )
    assert status == 403
    status, _, _ = _request(
        server, "POST", "/api/action", json.dumps({"action": "keep"}), {"Origin": f"http://127.0.0.1:{server.port}"}
    )
    assert status == 200
    status, _, _ = _request(server, "POST", "/api/state", "{}")
    assert status == 404
    for junk in (
        b"GARBAGE\r\n\r\n",
        b"GET\r\n\r\n",
        b"GET / HTTP/9.9\r\n\r\n",
        b"\x16\x03\x01\x00\xa5\x01\x00\x00\xa1",
        b"GET /" + b"a" * 70000 + b" HTTP/1.1\r\n\r\n",
    ):
        reply = _raw(server, junk)
        assert reply == b"" or re.match(rb"HTTP/1\.[01] 4\d\d", reply), reply[:80]
        assert b"Traceback" not in reply
    _alive(server)


def test_the_command_prints_its_port_and_serves(tmp_path):
    env = dict(os.environ)
    save = tmp_path / "mine.lig"
    cmd = [sys.executable, "-m", "liganimate", "studio", "--no-browser", "--seed", "77", "--save", str(save)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        lines = []
        deadline = time.time() + 60
        while time.time() < deadline:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
                break
        else:
            pytest.fail("no address printed: " + "".join(lines))
        assert "seed 77" in lines[0]
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        conn.request("GET", "/api/state")
        state = json.loads(conn.getresponse().read())
        assert state["seed"] == 77 and state["savePath"] == str(save)
    finally:
        proc.send_signal(signal.SIGINT)
        _out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    "args, message",
    [
        (["--model", "NOSUCH"], "no standard library offers a model called NOSUCH"),
        (["--save", "poses.txt"], "does not end in .lig"),
        (["--motion", "HUMANOID"], "cannot both be called HUMANOID"),
        (["--save", "/no/such/folder/x.lig"], "there is no folder"),
    ],
)
def test_the_command_refuses_bad_choices(tmp_path, args, message):
    r = liganimate("studio", "--no-browser", *args, cwd=tmp_path, timeout=120)
    assert r.returncode == 1 and message in r.stderr and "Traceback" not in r.stderr


def test_a_program_file_and_its_models(tmp_path):
    prog = tmp_path / "two.lig"
    prog.write_text(
        "      GRAPHICAL A, B\n      MODEL ONE, TWO\n"
        "      A :- BOX WIDTH 1.0, HEIGHT 0.2, DEPTH 0.2\n      B :- BOX WIDTH 0.2, HEIGHT 1.0, DEPTH 0.2\n"
        "      ONE :- JOINT 1, A, (0.5, 0.0, 0.0), B, (0.0, -0.5, 0.0), (-90.0, 90.0)\n"
        "      TWO :- JOINT 2, B, (0.0, 0.5, 0.0), A, (-0.5, 0.0, 0.0), (0.0, 0.0), (-45.0, 45.0)\n",
        encoding="utf-8",
    )
    with pytest.raises(LigError, match="several models: ONE, TWO"):
        studio_model(str(prog), None)
    fig, name, _ = studio_model(str(prog), "two")
    assert name == "TWO" and fig.joint_ids == (2,)
    with pytest.raises(LigError, match="has no model called ONF") as info:
        studio_model(str(prog), "ONF")
    assert info.value.hint == "did you mean ONE?"
    bad = tmp_path / "bad.lig"
    bad.write_text("X = (1,\n", encoding="utf-8")
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "studio", "--no-browser", str(bad)],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert r.returncode == 1 and "bad.lig:1:" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("lengths", [["+2"], ["0_2"], ["2", "3"], ["2", "2"], ["\u0662"]])
def test_a_content_length_must_be_one_and_digits_only(server, lengths):
    # Issue 24: "+2" and "0_2" parsed as lengths, and two different headers were accepted.
    head = "".join(f"Content-Length: {n}\r\n" for n in lengths)
    start = f"POST /api/action HTTP/1.1\r\nHost: 127.0.0.1:{server.port}\r\nContent-Type: application/json\r\n"
    payload = (start + head + "\r\n{}").encode("utf-8")
    answer = _raw(server, payload)
    assert answer.startswith(b"HTTP/1.1 400 ") or answer.startswith(b"HTTP/1.0 400 "), answer[:80]
    assert b"Content-Length is not a length" in answer
    _alive(server)
