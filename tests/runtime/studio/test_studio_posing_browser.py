"""The studio as a posing tool, in headless Chromium: a slider sets an angle; kept poses are reordered, deleted, timed, played and saved.

The saved library is then played by `liganimate run` and its pose record
compared with the poses kept, at their frames.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from browser import Browser, require_chromium
from commands import liganimate
from studio_support import running_studio


@pytest.fixture(scope="module")
def studio(tmp_path_factory, humanoid):
    require_chromium()
    save = tmp_path_factory.mktemp("posing") / "posed.lig"
    with (
        running_studio(humanoid, "HUMANOID", save, seed=77) as (server, session),
        Browser(1300, 1100, log_network=True) as b,
    ):
        b.driver.get(server.url)
        _settle(b)
        yield b, session, save


def _settle(b, timeout=30):
    deadline = time.time() + timeout
    while time.time() < deadline:
        if b.driver.execute_script("return !!(window.ligStudio && ligStudio.state() && !ligStudio.busy())"):
            return b.driver.execute_script("return ligStudio.state()")
        time.sleep(0.05)
    pytest.fail("the studio page did not settle: " + b.driver.find_element("id", "status").text)


def _choose_joint(b, link: int) -> None:
    from selenium.webdriver.support.ui import Select

    Select(b.driver.find_element("id", "joint")).select_by_value(str(link))


def _slide_to_end(b, axis: str, key) -> None:
    slider = b.driver.find_element("id", f"ang{axis}")
    slider.click()  # focus (a click on its middle may move it; the key below decides)
    slider.send_keys(key)
    b.driver.execute_script("arguments[0].blur()", slider)  # a range input sends 'change' on commit


def test_a_slider_sets_an_angle_and_the_pose_changes(studio):
    from selenium.webdriver.common.keys import Keys

    b, session, _ = studio
    g = session.generator
    arm = g.figure.links_named("R_UPPERARM")[0]
    joint = g.joint_of_link(arm)
    ext = np.asarray(g.figure.extremes[joint]).reshape(3, 2)
    before = b.canvas("#current")
    _choose_joint(b, arm)
    _slide_to_end(b, "Z", Keys.END)
    state = _settle(b)
    assert state["angles"][0][joint][2] == pytest.approx(ext[2, 1])
    assert g.current[joint][2] == ext[2, 1]
    assert "R_UPPERARM (joint 11) set to" in b.driver.find_element("id", "status").text
    assert (b.canvas("#current") != before).sum() > 200
    # The number field shows the same angle; typing another sets it, within the extremes.
    number = b.driver.find_element("id", "numZ")
    assert float(number.get_attribute("value")) == pytest.approx(ext[2, 1])
    number.send_keys(Keys.CONTROL, "a")  # (clear() would send a 'change' of its own)
    number.send_keys("-30", Keys.TAB)
    state = _settle(b)
    assert state["angles"][0][joint][2] == pytest.approx(max(-30.0, ext[2, 0]))
    # Locked axes cannot be moved.
    locked = [k for k in range(3) if ext[k, 0] == ext[k, 1]]
    for k in locked:
        assert not b.driver.find_element("id", "ang" + "XYZ"[k]).is_enabled()


def test_the_floor_sits_under_the_lowest_point(studio):
    b = studio[0]
    with_floor = b.canvas("#current")
    b.driver.find_element("id", "floor").click()
    without = b.canvas("#current")
    b.driver.find_element("id", "floor").click()

    # The floor is a light grey plane under the feet (lighter than the figure, darker than the
    # background), absent when unticked.
    def light_grey(img):
        return ((img > 185) & (img < 238)).sum()

    assert light_grey(with_floor) > 5000 and light_grey(without) < light_grey(with_floor) / 4


def test_candidates_fill_their_tiles(studio):
    b = studio[0]
    for i in range(9):
        img = b.canvas(f"#cand{i}")
        rows, cols = np.nonzero(img < 200)
        assert rows.max() - rows.min() > 0.55 * img.shape[0] or cols.max() - cols.min() > 0.55 * img.shape[1], i


def _kept_button(b, k: int, name: str):
    return b.driver.find_element("css selector", f"#kept{k} button.{name}")


def test_keep_reorder_delete_time_play_save_and_run(studio, tmp_path):
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select

    b, session, save = studio
    g = session.generator
    thigh = g.figure.links_named("L_THIGH")[0]
    poses = []
    for end in (Keys.HOME, Keys.END, Keys.HOME):  # three different poses, each kept
        _choose_joint(b, thigh)
        _slide_to_end(b, "Z", end)
        _settle(b)
        b.driver.find_element("id", "keep").click()
        _settle(b)
        poses.append(g.current.copy())
        b.driver.find_element("id", "stand").click()
        _settle(b)
    assert len(g.kept) >= 3
    base = len(g.kept) - 3  # poses kept by earlier tests of this module, if any
    assert len(b.driver.find_elements("css selector", "#strip .thumb")) == len(g.kept)
    # Reorder: the last kept pose one place earlier.
    _kept_button(b, base + 2, "earlier").click()
    _settle(b)
    assert np.array_equal(g.kept[base + 1], poses[2]) and np.array_equal(g.kept[base + 2], poses[1])
    # Delete the (now) last one.
    _kept_button(b, base + 2, "delete").click()
    state = _settle(b)
    assert len(g.kept) == base + 2 and state["kept"] == base + 2
    assert len(b.driver.find_elements("css selector", "#strip .thumb")) == base + 2
    # Its frame: 40 frames after the one before.
    last = base + 1
    frame_input = b.driver.find_element("css selector", f"#kept{last} input")
    target = g.kept_frames[last - 1] + 40
    frame_input.send_keys(Keys.CONTROL, "a")
    frame_input.send_keys(str(target), Keys.TAB)
    state = _settle(b)
    assert state["keptFrames"][last] == target
    Select(b.driver.find_element("id", "interp")).select_by_value("ACCDCC")
    state = _settle(b)
    assert state["interpolation"] == "ACCDCC"
    # Play: the current view steps through every frame of the motion.
    b.driver.find_element("id", "play").click()
    _settle(b)
    deadline = time.time() + 60
    while time.time() < deadline and not b.driver.execute_script("return ligStudio.playing().done"):
        time.sleep(0.1)
    assert b.driver.execute_script("return ligStudio.playing().shown") == target
    # Save, then play the saved library with `liganimate run` and compare its poses with the kept ones.
    b.driver.find_element("id", "save").click()
    state = _settle(b)
    assert state["saved"] and save.is_file()
    text = save.read_text(encoding="utf-8")
    assert "INTERPOLATE ACCDCC" in text and f"FRAME {target} POSITION" in text
    program = tmp_path / "play.lig"
    program.write_text(
        f"      LOAD HUMANOID, POSES FROM '{save}'\n      INITIALIZE SCENE 1\n"
        f"      STARTSCENE LENGTH {target + 1}\n        ANIMATE HUMANOID FROM 0 TO {target} USING POSES\n"
        "      ENDSCENE\n      SHOOTSCENES\n",
        encoding="utf-8",
    )
    record = tmp_path / "poses.jsonl"
    r = liganimate("run", str(program), "-o", str(tmp_path / "f"), "--poses", str(record), "--quiet", timeout=300)
    assert r.returncode == 0, r.stderr
    ticks = {rec["tick"]: rec for rec in map(json.loads, record.read_text(encoding="utf-8").splitlines())}
    ids = [str(j.id) for j in g.figure.joints]
    for pose, frame in zip(g.kept, state["keptFrames"]):
        played = np.array([ticks[frame]["joints"][i] for i in ids])
        assert np.allclose(played, pose, atol=1e-6), frame
