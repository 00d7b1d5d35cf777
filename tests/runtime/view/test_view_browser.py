"""The viewer in headless Chromium: it draws what `liganimate run` draws, scrubs, orbits, names segments, stays offline."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from browser import Browser, require_chromium
from paths import ROOT_DIR
from PIL import Image

ROOT = ROOT_DIR
APPENDIX = os.path.join(ROOT, "examples", "appendix_a.lig")
FIVE = os.path.join(ROOT, "benchmarks", "five_humans.lig")
MAILBOX = os.path.join(ROOT, "examples", "mailbox.lig")  # morphing segments: SCALE LINK and SHAPE LINK tracks

TWO_SCENES = """\
      GRAPHICAL A, B, FLOOR
      MODEL ARM
      MOTION SWING
      A :- BOX WIDTH 0.4, HEIGHT 2.0, DEPTH 0.4, LIGHTNESS 30.0
      B :- BOX WIDTH 0.3, HEIGHT 1.6, DEPTH 0.3, LIGHTNESS 50.0
      FLOOR :- BOX AT (0.0, -1.1, 0.0), WIDTH 6.0, HEIGHT 0.1, DEPTH 3.0, LIGHTNESS 85.0
      ARM :- JOINT 7, A, (0.0, 1.0, 0.0), B, (0.0, -0.8, 0.0), (-90.0, 90.0), (-180.0, 180.0), (-120.0, 120.0)
      STARTMOTION SWING
        JOINT 7 POSITION 0.0, 0.0, -100.0
          FRAME 20 POSITION 0.0, 90.0, 100.0
      ENDMOTION
      INITIALIZE SCENE 1
        VIEW POINT = (0.0, 1.0, 8.0)
        VIEW WIDTH = 6.0
        BACKGROUND FLOOR
      STARTSCENE LENGTH 21
        ANIMATE ARM FROM 0 TO 20 USING SWING
      ENDSCENE
      INITIALIZE SCENE 2
        VIEW POINT = (6.0, 6.0, 0.5)
        VIEW WIDTH = 9.0
      STARTSCENE LENGTH 8 SAMEFRAME 2
        ARM :- ARM <ROT Y 20.0>
        ANIMATE ARM FROM 0 TO 7 USING SWING <SCALE FRAMES 0.4>
      ENDSCENE
      SHOOTSCENES
"""


# The README's walk: no VIEW, so the modern look frames it.
NO_VIEW = """\
LOAD HUMANOID, WALK FROM 'humanoid'
INITIALIZE SCENE 1
STARTSCENE LENGTH 48
ANIMATE HUMANOID FROM 0 TO 47 USING WALK REPEAT
ENDSCENE
SHOOTSCENES
"""


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """Viewer pages and `liganimate run` frames of three programs (five figures shortened to 60 ticks)."""
    require_chromium()
    tmp = tmp_path_factory.mktemp("view")
    five = Path(FIVE).read_text(encoding="utf-8").replace("STARTSCENE LENGTH 1000", "STARTSCENE LENGTH 60")
    five = re.sub(r"FROM 0 TO 999 ", "FROM 0 TO 59 ", five)
    sources = {"appendix": APPENDIX, "five": tmp / "five.lig", "two": tmp / "two.lig", "walk": tmp / "walk.lig"}
    sources["mailbox"] = MAILBOX
    (tmp / "five.lig").write_text(five, encoding="utf-8")
    (tmp / "walk.lig").write_text(NO_VIEW, encoding="utf-8")
    (tmp / "two.lig").write_text(TWO_SCENES, encoding="utf-8")
    out = {}
    for name, src in sources.items():
        page = tmp / f"{name}.html"
        for cmd in (
            [sys.executable, "-m", "liganimate", "view", str(src), "-o", str(page), "--quiet"],
            # The viewer's flat shading is the thesis look's.
            [sys.executable, "-m", "liganimate", "run", str(src), "-o", str(tmp / name), "--quiet", "--look", "thesis"],
        ):
            r = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=600)
            assert r.returncode == 0, r.stderr
        out[name] = (page, tmp / name)
    # The walk and Appendix A in the modern look too: the default framing, and the contact shadow.
    for name in ("walk", "appendix"):
        cmd = [sys.executable, "-m", "liganimate", "run", str(sources[name]), "-o", str(tmp / f"{name}_modern")]
        r = subprocess.run(cmd + ["--quiet"], check=False, capture_output=True, text=True, timeout=600)
        assert r.returncode == 0, r.stderr
        out[f"{name}_modern"] = (None, tmp / f"{name}_modern")
    return out


@pytest.fixture(scope="module")
def browser():
    require_chromium()
    with Browser(log_network=True) as b:
        yield b


def _open(browser, page, size="640x480", look="thesis"):
    # The thesis look by default: the comparisons with `liganimate run --look thesis` need its flat shading.
    browser.driver.get("about:blank")  # a new document even when only the #fragment would differ
    browser.driver.get(page.as_uri() + f"#size={size}&look={look}")
    deadline = time.time() + 30
    while time.time() < deadline:
        if browser.driver.execute_script("return !!(window.ligViewer && window.ligViewer.ready)"):
            return
        time.sleep(0.05)
    pytest.fail("the viewer did not start: " + browser.driver.find_element("id", "info").text)


def _frame(browser, scene_index, image):
    browser.driver.execute_script(f"ligViewer.setScene({scene_index}); ligViewer.setFrame({image});")
    return browser.canvas()


def _run_image(folder, scene_id, image):
    return np.asarray(Image.open(folder / f"scene{scene_id}" / f"{image:05d}.png").convert("L"))


@pytest.mark.parametrize(
    "name, scene_index, scene_id, images",
    [
        ("five", 0, 1, [0, 17, 59]),
        ("appendix", 0, 1, [0]),  # SAMEFRAME 6: six ticks in one picture
        ("two", 0, 1, [0, 10, 20]),  # a background object
        ("two", 1, 2, [0, 3]),  # a camera from above at an angle, SAMEFRAME 2
        ("mailbox", 0, 1, [0, 30, 41, 60]),  # segments that change shape and size
    ],
)
def test_the_canvas_shows_what_liganimate_run_draws(pages, browser, name, scene_index, scene_id, images):
    page, frames = pages[name]
    _open(browser, page)
    for image in images:
        mine = _frame(browser, scene_index, image)
        theirs = _run_image(frames, scene_id, image)
        assert mine.shape == theirs.shape == (480, 640)
        a, b = mine < 255, theirs < 255
        assert b.sum() > 500, "the rasterized frame should show something"
        iou = (a & b).sum() / (a | b).sum()
        assert iou > 0.97, (name, image, iou)
        # Flat shading like the rasterizer: the same grey wherever both drew.
        same = (mine == theirs)[a & b].mean()
        assert same > 0.97, (name, image, same)


def test_the_modern_look_lights_and_outlines_what_the_thesis_look_draws_flat(pages, browser):
    page, _ = pages["five"]
    _open(browser, page, look="thesis")
    flat = _frame(browser, 0, 17)
    _open(browser, page, look="modern")
    modern = _frame(browser, 0, 17)
    assert flat[5, 5] == 255 and abs(int(modern[5, 5]) - 244) <= 1  # the modern look's grey background
    drawn_flat, drawn_modern = flat < 255, modern < 240
    iou = (drawn_flat & drawn_modern).sum() / (drawn_flat | drawn_modern).sum()
    assert iou > 0.8  # the same figures where they were (the outlines widen them a little)
    # Outlines: pixels far darker than any shade the thesis look draws, along the figures' edges.
    assert (modern < flat[drawn_flat].min() - 20).sum() > 300
    # Lit faces and smoothed edges: many more levels than the flat look's few.
    assert len(np.unique(modern)) > 3 * len(np.unique(flat))


def test_a_scene_without_view_keeps_the_thesis_camera_in_the_thesis_look(pages, browser):
    page, frames = pages["walk"]
    _open(browser, page, look="thesis")
    start = browser.driver.execute_script("return ligViewer.sceneCamera()")
    assert start == {"eye": [0, 0, 10], "target": [0, 0, 0], "k": 1}  # VIEW POINT (0, 0, 10), VIEW WIDTH 10
    _open(browser, page, look="modern")
    assert browser.driver.execute_script("return ligViewer.sceneCamera()")["eye"] != [0, 0, 10]


def test_a_scene_without_view_starts_from_the_camera_liganimate_run_uses(pages, browser, monkeypatch, tmp_path):
    import liganimate
    from liganimate.runtime.render import frames

    used = []
    view = frames.Renderer._view
    monkeypatch.setattr(frames.Renderer, "_view", lambda self, *a: used.append(view(self, *a)) or used[-1])
    liganimate.load(str(pages["walk"][0].with_suffix(".lig"))).render(tmp_path, size=(640, 480), quiet=True)
    (eye, width, target) = used[0]
    assert set(used) == {used[0]}  # one camera for the whole scene
    _open(browser, pages["walk"][0], look="modern")
    start = browser.driver.execute_script("return ligViewer.sceneCamera()")
    assert start["eye"] == pytest.approx(eye, rel=1e-12) and start["target"] == pytest.approx(target, rel=1e-12)
    distance = float(np.linalg.norm(np.subtract(eye, target)))
    assert start["k"] * distance == pytest.approx(width, rel=1e-12)
    # The picture frames the walker where `liganimate run` does: the drawn box within a few pixels.
    mine, theirs = _frame(browser, 0, 0), _run_image(pages["walk_modern"][1], 1, 0)
    boxes = []
    for img in (mine, theirs):
        rows, cols = np.nonzero(img < 200)
        boxes.append((rows.min(), rows.max(), cols.min(), cols.max()))
    assert np.abs(np.subtract(*boxes)).max() <= 3, boxes
    assert boxes[0][1] - boxes[0][0] > 100  # framed: the figure is not lost in a corner
    # Orbiting leaves the scene camera; "Scene camera" comes back to run's.
    browser.driver.execute_script(
        "ligViewer.restore({scene: 1, image: 0, cam: {eye: [9, 9, 9], target: [0, 0, 0], k: 1}})"
    )
    assert browser.driver.execute_script("return ligViewer.camera()")["eye"] == [9, 9, 9]
    browser.driver.find_element("id", "reset").click()
    assert browser.driver.execute_script("return ligViewer.camera()") is None
    assert np.array_equal(browser.canvas(), mine)


def test_a_scene_with_view_keeps_its_view_in_the_modern_look(pages, browser):
    _open(browser, pages["two"][0], look="modern")
    start = browser.driver.execute_script("return ligViewer.sceneCamera()")
    assert start["eye"] == pytest.approx([0.0, 1.0, 8.0]) and start["target"] == [0, 0, 0]
    assert start["k"] * np.linalg.norm(start["eye"]) == pytest.approx(6.0, rel=1e-6)


def _ground_agrees(mine, theirs, rows) -> int:
    """Assert that the viewer's ground (under the figures' middle) is run's, shadow included; return its shadowed pixels."""
    # The ground under and around the figures: pixels both show bright (the background, lit faces aside).
    ground = (mine > 205) & (theirs > 205)
    ground[: (rows.min() + rows.max()) // 2] = False
    shadowed = ground & (theirs < 242)
    assert shadowed.sum() > 500, "liganimate run draws a contact shadow here"
    assert (np.abs(mine - theirs)[ground] <= 2).mean() > 0.995
    assert 0.8 < (ground & (mine < 242)).sum() / shadowed.sum() < 1.25
    return int(shadowed.sum())


def test_the_contact_shadow_of_a_scene_with_view_is_liganimate_runs(pages, browser):
    _open(browser, pages["appendix"][0], look="modern")
    mine = _frame(browser, 0, 0).astype(int)  # six squat stages (SAMEFRAME 6), seen from the side
    theirs = _run_image(pages["appendix_modern"][1], 1, 0).astype(int)
    _ground_agrees(mine, theirs, np.nonzero(theirs < 200)[0])


def test_the_contact_shadow_is_liganimate_runs_and_the_thesis_look_has_none(pages, browser):
    _open(browser, pages["walk"][0], look="modern")
    mine = _frame(browser, 0, 0).astype(int)
    theirs = _run_image(pages["walk_modern"][1], 1, 0).astype(int)
    rows, cols = np.nonzero(theirs < 200)
    foot = rows.max()  # the planted foot's lowest pixel
    _ground_agrees(mine, theirs, rows)
    # Just under the foot the background is darker than far from the figure.
    below = mine[foot + 2 : foot + 8, cols.min() : cols.max() + 1]
    assert below.min() < 240 and mine[foot + 60 :, :].min() == 244 == mine[5, 5]
    # The thesis look: no shadow, white everywhere the figure is not.
    _open(browser, pages["walk"][0], look="thesis")
    flat = _frame(browser, 0, 0)
    rows, cols = np.nonzero(flat < 255)
    assert (flat[rows.max() + 1 :] == 255).all() and (flat[:, cols.max() + 1 :] == 255).all()


def test_the_notebook_display_draws_the_shadow_from_runs_camera(pages, browser, tmp_path):
    import liganimate

    _open(browser, pages["walk"][0], look="modern")
    expected = browser.driver.execute_script("return ligViewer.sceneCamera()")
    # A notebook shows the viewer in a sandboxed <iframe srcdoc>: a page holding just that.
    shown = liganimate.load(str(pages["walk"][0].with_suffix(".lig")))._repr_html_()
    host = tmp_path / "notebook.html"
    host.write_text(f"<!DOCTYPE html><html><body>{shown}</body></html>", encoding="utf-8")
    browser.driver.get("about:blank")
    browser.driver.get(host.as_uri())
    browser.driver.switch_to.frame(browser.driver.find_element("tag name", "iframe"))
    try:
        from selenium.webdriver.support.ui import WebDriverWait

        # Waits for the frame's viewer, however loaded the machine; the bound only stops a hang.
        WebDriverWait(browser.driver, 60, poll_frequency=0.05).until(
            lambda d: d.execute_script("return !!(window.ligViewer && window.ligViewer.ready)"),
            "the notebook's viewer did not start",
        )
        start = browser.driver.execute_script("return ligViewer.sceneCamera()")
        assert start == expected, (start, expected)
        # The frame's script can run before the frame has its size (no resize event follows):
        # the picture must still grow to the largest 4:3 the frame's stage holds.
        fits = (
            "var b = document.getElementById('stage').getBoundingClientRect(), c = document.getElementById('view');"
            "var w = Math.floor(Math.min(b.width, b.height * 4 / 3));"
            "return w > 64 && c.width === w ? w : null;"
        )
        WebDriverWait(browser.driver, 30, poll_frequency=0.05).until(
            lambda d: d.execute_script(fits),
            "the notebook's viewer did not grow to fill its frame",
        )
        img = browser.canvas().astype(int)
        rows, cols = np.nonzero(img < 200)
        assert len(rows), "the notebook's viewer drew no figure"
        below = img[rows.max() + 2 : rows.max() + 8, cols.min() : cols.max() + 1]
        # The grey background, darker under the feet.
        assert img[0, 0] == 244 and below.min() < 240, (img.shape, img[0, 0], below.min())
    finally:
        browser.driver.switch_to.default_content()


def test_the_picture_follows_its_stage_without_a_window_resize(pages, browser):
    # The stage can change size with no resize event: a notebook frame getting its size late,
    # or the read-out line growing.  The picture must follow the stage, not the window.
    _open(browser, pages["walk"][0], size="")
    fits = (
        "var b = document.getElementById('stage').getBoundingClientRect(), c = document.getElementById('view');"
        "return [Math.floor(Math.min(b.width, b.height * 4 / 3)), c.width];"
    )
    first, have = browser.driver.execute_script(fits)
    assert first == have > 300, (first, have)
    browser.driver.execute_script("document.getElementById('info').style.minHeight = '300px'")
    deadline = time.time() + 30
    while time.time() < deadline:
        want, have = browser.driver.execute_script(fits)
        if want == have:
            break
        time.sleep(0.05)
    assert want == have < first - 100, (first, want, have)


def test_moving_the_scrubber_changes_the_picture(pages, browser):
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    _open(browser, pages["five"][0])
    before = browser.canvas()
    label = browser.driver.find_element("id", "frame").text
    scrub = browser.driver.find_element("id", "scrub")
    scrub.click()
    scrub.send_keys(Keys.END)
    after = browser.canvas()
    assert browser.driver.find_element("id", "frame").text == "frame 59 / 59" != label
    assert browser.driver.find_element("id", "tick").text == "tick 59"
    assert (before != after).sum() > 200
    assert np.array_equal(after, _frame(browser, 0, 59))
    # Playing moves on by itself.
    browser.driver.execute_script("ligViewer.setFrame(0)")
    browser.driver.find_element("id", "play").click()
    # Waits for the event (a frame shown after 0), however slow the machine; the bound only stops a hang.
    WebDriverWait(browser.driver, 60, poll_frequency=0.05).until(
        lambda d: d.execute_script("return ligViewer.frame()") > 0
    )
    browser.driver.find_element("id", "play").click()
    stopped = browser.driver.execute_script("return ligViewer.frame()")
    assert stopped > 0


def test_orbit_and_back_to_the_scene_camera(pages, browser):
    from selenium.webdriver.common.action_chains import ActionChains

    _open(browser, pages["two"][0])
    start = browser.canvas()
    canvas = browser.driver.find_element("id", "view")
    ActionChains(browser.driver).move_to_element(canvas).click_and_hold().move_by_offset(120, 40).release().perform()
    turned = browser.canvas()
    assert (turned != start).sum() > 500
    browser.driver.find_element("id", "reset").click()
    assert np.array_equal(browser.canvas(), start)


def test_scene_selector(pages, browser):
    from selenium.webdriver.support.ui import Select

    _open(browser, pages["two"][0])
    first = browser.canvas()
    Select(browser.driver.find_element("id", "sceneSel")).select_by_index(1)
    assert browser.driver.find_element("id", "frame").text == "frame 0 / 3"
    assert browser.driver.find_element("id", "tick").text == "ticks 0\u20131"
    assert (browser.canvas() != first).sum() > 500


def test_hovering_a_segment_names_its_joint_angles_and_extremes(pages, browser):
    from selenium.webdriver.common.action_chains import ActionChains

    _open(browser, pages["two"][0])
    browser.driver.execute_script("ligViewer.setFrame(20)")
    img = browser.canvas()
    # The forearm B is drawn at lightness 50 and 75: greys 128 and 191 (round half up of L * 2.55).
    ys, xs = np.nonzero((img == 128) | (img == 191))
    assert len(xs) > 50
    k = int(np.argmin((xs - xs.mean()) ** 2 + (ys - ys.mean()) ** 2))
    canvas = browser.driver.find_element("id", "view")
    ActionChains(browser.driver).move_to_element_with_offset(canvas, int(xs[k]) - 320, int(ys[k]) - 240).perform()
    info = browser.driver.find_element("id", "info").text
    assert "ARM: segment B" in info
    assert "joint 7 at tick 20: X 0.00\u00b0  Y 90.00\u00b0  Z 100.00\u00b0" in info
    assert "extremes: X (-90, 90)  Y (-180, 180)  Z (-120, 120)" in info
    # Click pins it; the highlighted segment is tinted.
    ActionChains(browser.driver).click().perform()
    assert "pinned" in browser.driver.find_element("id", "info").text
    assert (browser.canvas() != img).sum() > 20


def test_the_page_makes_no_request_beyond_its_own_file(pages, tmp_path):
    from selenium.webdriver.support.ui import WebDriverWait

    require_chromium()
    page = pages["five"][0]
    with Browser(log_network=True) as b:
        _open(b, page)
        b.driver.execute_script("ligViewer.setFrame(30); ligViewer.play(true);")
        # Several frames drawn while playing (whatever the machine's speed), then the network log.
        WebDriverWait(b.driver, 60, poll_frequency=0.05).until(
            lambda d: d.execute_script("return ligViewer.frame()") >= 33
        )
        requests = b.requests()
    mine = {url.split("#")[0] for url, doc in requests if doc.split("#")[0] == page.as_uri()}
    assert mine == {page.as_uri()}, "the page's only request is for its own file"
    # Nor did anything else in the browser go on the network (it opened only this file and about:blank).
    assert not [url for url, _ in requests if re.match(r"(https?|wss?|ftp):", url)]


def test_a_thousand_frame_five_figure_scene_opens_quickly(tmp_path):
    """Under 10 MB and drawn within 2 s of navigation in headless Chromium."""
    require_chromium()
    page = tmp_path / "five.html"
    r = subprocess.run(
        [sys.executable, "-m", "liganimate", "view", FIVE, "-o", str(page), "--quiet"],
        check=False,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    assert page.stat().st_size < 10_000_000
    with Browser() as b:
        best = []
        for _ in range(2):
            _open(b, page)
            best.append(b.driver.execute_script("return ligViewer.ready"))
        assert b.driver.execute_script("return ligViewer.frames()") == 1000
        assert (b.canvas() < 255).sum() > 1000
    assert min(best) < 2000, best
