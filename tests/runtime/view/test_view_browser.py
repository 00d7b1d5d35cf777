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


def test_a_scene_without_view_is_framed_in_the_modern_look(pages, browser):
    page, _ = pages["walk"]
    _open(browser, page, look="thesis")
    small = _frame(browser, 0, 0)
    _open(browser, page, look="modern")
    framed = _frame(browser, 0, 0)
    rows_small = np.nonzero((small < 250).any(axis=1))[0]
    rows_framed = np.nonzero((framed < 230).any(axis=1))[0]
    # The thesis' camera shows the 1.8-unit figure in a view 10 units wide; the framing fills the picture's height.
    assert rows_small.max() - rows_small.min() < 0.35 * small.shape[0]
    assert rows_framed.max() - rows_framed.min() > 1.4 * (rows_small.max() - rows_small.min())


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
