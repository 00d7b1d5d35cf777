"""The studio in headless Chromium: nine candidates, a click takes a limb, Keep pose and Save write a library `liganimate run` accepts."""

from __future__ import annotations

import time

import numpy as np
import pytest
from browser import Browser, require_chromium
from commands import liganimate
from studio_support import running_studio


@pytest.fixture(scope="module")
def studio(tmp_path_factory, humanoid):
    require_chromium()
    save = tmp_path_factory.mktemp("studio") / "posed.lig"
    with (
        running_studio(humanoid, "HUMANOID", save, seed=2024) as (server, session),
        Browser(1300, 950, log_network=True) as b,
    ):
        b.driver.get(server.url)
        _settle(b)
        yield b, server, session, save


def _settle(b, timeout=30):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if b.driver.execute_script("return !!(window.ligStudio && ligStudio.state() && !ligStudio.busy())"):
            return b.driver.execute_script("return ligStudio.state()")
        time.sleep(0.05)
    pytest.fail("the studio page did not settle: " + b.driver.find_element("id", "status").text)


def _click_limb(b, view: int, link: int) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    point = b.driver.execute_script(f"return ligStudio.linkPoint({view}, {link})")
    assert point is not None, f"link {link} is not visible in view {view}"
    canvas = b.driver.find_element("id", "current" if view == 0 else f"cand{view - 1}")
    ActionChains(b.driver).move_to_element_with_offset(canvas, round(point[0]), round(point[1])).click().perform()


def test_the_page_shows_nine_candidates(studio):
    b = studio[0]
    images = [b.canvas(f"#cand{i}") for i in range(9)]
    assert len(b.driver.find_elements("css selector", "#grid canvas")) == 9
    for img in images:
        assert (img < 250).sum() > 300  # a figure is drawn in each
    # ...and they are nine different poses.
    for i in range(9):
        for j in range(i + 1, 9):
            assert (images[i] != images[j]).sum() > 100, (i, j)
    assert b.driver.find_element("id", "generation").text == "generation 1"
    assert b.driver.find_element("id", "seed").get_attribute("value") == "2024"


def test_a_click_takes_a_limb_then_keep_and_save(studio, tmp_path):
    b, _, session, save = studio
    g = session.generator
    thigh = g.figure.links_named("R_THIGH")[0]
    joint = g.joint_of_link(thigh)
    before = g.current.copy()
    _click_limb(b, 4, thigh)  # candidate 4
    state = _settle(b)
    assert "took R_THIGH (joint 31) from candidate 4" in b.driver.find_element("id", "status").text
    assert np.array_equal(g.current[joint], g.candidates[3, joint])
    assert not np.array_equal(g.current[joint], before[joint])
    assert np.allclose(state["angles"][0][joint], g.candidates[3, joint], atol=1e-4)
    current = b.canvas("#current")
    b.driver.find_element("id", "keep").click()
    _settle(b)
    b.driver.find_element("id", "next").click()
    _settle(b)
    assert b.driver.find_element("id", "generation").text == "generation 2"
    arm = g.figure.links_named("L_UPPERARM")[0]
    _click_limb(b, 7, arm)
    _settle(b)
    assert (b.canvas("#current") != current).sum() > 50
    b.driver.find_element("id", "keep").click()
    _settle(b)
    b.driver.find_element("id", "save").click()
    state = _settle(b)
    assert state["saved"] and state["kept"] == 2
    assert "saved 2 pose(s)" in b.driver.find_element("id", "status").text
    assert save.is_file()
    r = liganimate("run", str(save), "-o", str(tmp_path / "f"), "--quiet", timeout=300)
    assert r.returncode == 0, r.stderr
    play = tmp_path / "play.lig"
    play.write_text(
        f"      LOAD HUMANOID, POSES FROM '{save}'\n      INITIALIZE SCENE 1\n"
        "      STARTSCENE LENGTH 25\n        ANIMATE HUMANOID FROM 0 TO 24 USING POSES\n"
        "      ENDSCENE\n      SHOOTSCENES\n",
        encoding="utf-8",
    )
    r = liganimate("run", str(play), "-o", str(tmp_path / "g"), "--quiet", timeout=300)
    assert r.returncode == 0, r.stderr


def test_undo_seed_and_twist_from_the_page(studio):
    b, _, session, _ = studio
    g = session.generator
    gen = g.generation
    b.driver.find_element("css selector", "input[name=mode][value=twist]").click()
    _settle(b)
    assert g.mode == "twist"
    b.driver.find_element("id", "next").click()
    _settle(b)
    assert g.generation == gen + 1
    b.driver.find_element("id", "undo").click()
    _settle(b)
    assert g.generation == gen
    seed = b.driver.find_element("id", "seed")
    seed.clear()
    seed.send_keys("31337")
    b.driver.find_element("id", "setSeed").click()
    _settle(b)
    assert g.seed == 31337 and g.generation == 1
    assert b.driver.find_element("id", "generation").text == "generation 1"
    # A limb clicked in the current pose is frozen (tinted) and no longer mutates.
    spine = g.figure.links_named("SPINE")[0]
    plain = b.canvas("#current")
    _click_limb(b, 0, spine)
    _settle(b)
    assert g.frozen[g.joint_of_link(spine)]
    assert (b.canvas("#current") != plain).sum() > 50


def test_the_page_talks_only_to_its_server(studio):
    b, server, _, _ = studio
    requests = [url for url, _ in b.requests() if not url.startswith(("chrome:", "data:", "about:"))]
    assert requests
    assert all(url.startswith(server.url) for url in requests), requests


def test_the_current_pose_casts_a_contact_shadow_on_its_floor(studio):
    b = studio[0]
    from selenium.webdriver.common.action_chains import ActionChains

    floor_box = b.driver.find_element("id", "floor")
    assert floor_box.is_selected()
    ActionChains(b.driver).move_to_element(floor_box).perform()  # no limb under the pointer, none tinted
    on = b.canvas("#current").astype(int)
    feet = [b.driver.execute_script(f"return ligStudio.linkPoint(0, {link})") for link in (4, 8)]  # R_FOOT, L_FOOT
    floor_box.click()
    try:
        off = b.canvas("#current").astype(int)
    finally:
        floor_box.click()
    assert np.array_equal(b.canvas("#current"), on)
    # The floor's pixels are those the floor changes (the figure is the same); its ink lines aside,
    # they would all be one lit shade without the shadow.
    floor = (on != off) & (on > 150)
    near = np.zeros_like(floor)
    for dx, dy in feet:  # offsets from the canvas' centre
        x, y = dx + on.shape[1] // 2, dy + on.shape[0] // 2
        near[max(y - 30, 0) : y + 40, max(x - 40, 0) : x + 40] = True
    assert (floor & near).sum() > 200, feet
    lit = np.percentile(on[floor], 95)
    assert lit - np.percentile(on[floor & near], 5) >= 5, "the floor is darker around the feet"
    # Without the floor the shadow falls on the background (244 far from the figure), as in `liganimate run`.
    ground = (on != off) & near
    assert off[5, 5] == 244 and off[ground].min() < 240
