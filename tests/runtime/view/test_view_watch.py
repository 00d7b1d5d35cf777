"""``liganimate view --watch`` in Chromium: a save shows within a second, keeping the view; an error shows its diagnostic.

The server runs as a user starts it (``liganimate view p.lig --watch``, a
child process), the page in headless Chromium (tests/browser.py). A save
must show in the page within a second, with the scene, the frame and the
camera kept; a wrong program must show its diagnostic (file:line:col and the
line) over the last good picture; a fixed one reloads; Ctrl-C stops the
server cleanly. The screenshots are written to the test's folder.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from browser import Browser, require_chromium

PROGRAM = """GRAPHICAL B
MODEL M
MOTION SPIN
B :- BOX WIDTH {width}, HEIGHT 1.0, DEPTH 1.0, LIGHTNESS 60.0
M :- JOINT 1, B, (0.0, 0.0, 0.0), B, (1.0, 0.0, 0.0), (0, 0), (0, 0), (-180, 180)
SPIN[1, 1] = FRAME 0 POSITION (0.0, 0.0, 0.0)
SPIN[1, 2] = FRAME 8 POSITION (0.0, 0.0, 90.0)
INITIALIZE SCENE 1
  VIEW POINT = (2.0, 3.0, 8.0)
  VIEW WIDTH = 6.0
STARTSCENE LENGTH 9
  ANIMATE M FROM 0 TO 8 USING SPIN
ENDSCENE
SHOOTSCENES
"""


def _save(path, text: str) -> float:
    tmp = str(path) + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)  # as editors save: the new file whole, at once
    return time.monotonic()


def _until(predicate, limit: float, step: float = 0.02):
    end = time.monotonic() + limit
    while time.monotonic() < end:
        value = predicate()
        if value:
            return value
        time.sleep(step)
    return predicate()


@pytest.fixture
def server(tmp_path):
    prog = tmp_path / "p.lig"
    prog.write_text(PROGRAM.format(width="1.0"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "liganimate", "view", "p.lig", "--watch", "--no-browser"],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        head = [proc.stdout.readline(), proc.stdout.readline()]
        url = head[1].split()[1]
        assert url.startswith("http://127.0.0.1:"), head
        yield prog, url, proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)


def test_a_save_shows_within_a_second_keeping_the_view_and_an_error_shows_its_diagnostic(server, tmp_path):
    require_chromium()
    prog, url, proc = server
    with Browser(width=900, height=640) as b:
        d = b.driver
        d.get(url + "#size=480x320")
        assert _until(lambda: d.execute_script("return !!window.ligViewer"), 20)
        cam = {"eye": [5.0, 4.0, 6.0], "target": [0.5, 0.0, 0.0], "k": 0.6}
        d.execute_script("ligViewer.restore({scene: 1, image: 5, cam: arguments[0]}); window.__before = 1;", cam)
        before = b.canvas()

        saved = _save(prog, PROGRAM.format(width="2.5"))
        shown = _until(lambda: d.execute_script("return !window.__before && !!window.ligViewer"), 5)
        took = time.monotonic() - saved
        assert shown and took <= 1.0, f"the page showed the save after {took:.2f} s"
        assert d.execute_script("return ligViewer.frame()") == 5
        assert d.execute_script("return ligViewer.camera()") == cam
        after = b.canvas()
        assert after.shape == before.shape and np.count_nonzero(after != before) > 500, "the wider box is drawn"
        d.save_screenshot(str(tmp_path / "saved.png"))

        d.execute_script("window.__before = 1;")
        saved = _save(prog, PROGRAM.format(width="2.5").replace("HEIGHT 1.0,", "HEIGHT ,"))
        box = lambda: d.execute_script(  # noqa: E731
            "var e = document.getElementById('lig-diagnostic'); return e && !e.hidden ? e.textContent : '';"
        )
        text = _until(box, 5)
        assert time.monotonic() - saved <= 1.0
        assert text.startswith("p.lig:4:"), text
        assert "B :- BOX WIDTH 2.5, HEIGHT , DEPTH 1.0" in text and "error:" in text
        assert d.execute_script("return window.__before") == 1, "the last good page stays"
        assert np.array_equal(b.canvas(), after), "the picture is still drawn under the diagnostic"
        d.save_screenshot(str(tmp_path / "error.png"))

        _save(prog, PROGRAM.format(width="1.0"))
        assert _until(lambda: d.execute_script("return !window.__before && !!window.ligViewer"), 5)
        assert _until(lambda: box() == "", 2)

    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=20)
    assert proc.returncode == 0, err
    assert "stopped" in out and "Traceback" not in err


def test_the_server_answers_only_on_loopback_and_only_to_its_own_name(server):
    import http.client

    prog, url, proc = server
    port = int(url.rsplit(":", 1)[1].strip("/"))
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    conn.request("GET", "/watch", headers={"Host": "evil.example:80"})
    assert conn.getresponse().status == 403
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    conn.request("GET", "/watch")
    r = conn.getresponse()
    assert r.status == 200 and b'"version": 1' in r.read()
    import socket

    s = socket.socket()
    s.settimeout(2)
    try:
        addresses = [a[4][0] for a in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET)]
        outside = next((a for a in addresses if not a.startswith("127.")), None)
        if outside is not None:
            with pytest.raises(OSError):
                s.connect((outside, port))
    finally:
        s.close()
