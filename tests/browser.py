"""Headless Chromium for the browser tests: Debian's chromium and chromium-driver, driven by selenium.

:class:`Browser` starts a browser with no network of its own (no component
updates, sync or background requests), a fresh profile, and WebGL through
SwiftShader (there is no GPU).  When CI is set, a missing browser is an
error, not a skip.  benchmarks/view.py loads its page in the same browser.
"""

from __future__ import annotations

import base64
import io
import os
import shutil
import tempfile

import numpy as np

CHROMIUM = os.environ.get("LIGANIMATE_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("LIGANIMATE_CHROMEDRIVER", "/usr/bin/chromedriver")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--disable-extensions",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--force-device-scale-factor=1",
    "--hide-scrollbars",
]


def missing() -> list[str]:
    """What :class:`Browser` needs and this machine lacks: Chromium's and its driver's paths, the selenium package."""
    lacking = [p for p in (CHROMIUM, CHROMEDRIVER) if not os.path.exists(p)]
    try:
        import selenium  # noqa: F401
    except ImportError:
        lacking.append("the selenium package")
    return lacking


def require_chromium() -> None:
    """Skip (or, under CI, fail) when Chromium or its driver is missing."""
    # pytest is imported here, not at the top: benchmarks/view.py drives the
    # same browser through this module and runs without the test extra.
    import pytest

    lacking = missing()
    if lacking:
        why = (
            "browser tests need "
            + ", ".join(lacking)
            + " (apt-get install chromium chromium-driver; pip install -e '.[test]')"
        )
        if os.environ.get("CI"):
            pytest.fail(why)
        pytest.skip(why)


class Browser:
    """One headless Chromium with a throw-away profile; use as a context manager."""

    def __init__(self, width: int = 1000, height: int = 760, log_network: bool = False):
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service

        self.profile = tempfile.mkdtemp(prefix="lig-chromium-")
        opts = webdriver.ChromeOptions()
        opts.binary_location = CHROMIUM
        for flag in FLAGS:
            opts.add_argument(flag)
        opts.add_argument(f"--user-data-dir={self.profile}")
        opts.add_argument(f"--window-size={width},{height}")
        if log_network:
            opts.set_capability("goog:loggingPrefs", {"performance": "ALL"})
        self.driver = webdriver.Chrome(options=opts, service=Service(CHROMEDRIVER))
        self.driver.set_page_load_timeout(60)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        """Quit the browser and remove its profile."""
        try:
            self.driver.quit()
        finally:
            shutil.rmtree(self.profile, ignore_errors=True)

    def canvas(self, selector: str = "#view") -> np.ndarray:
        """A canvas's pixels as an (H, W) grey image (its red channel; everything drawn is grey)."""
        from PIL import Image

        url = self.driver.execute_script(f"return document.querySelector({selector!r}).toDataURL('image/png');")
        data = base64.b64decode(url.split(",", 1)[1])
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))[..., 0]

    def requests(self) -> list:
        """Every request since the last call, as (URL, URL of the document that made it) (needs ``log_network``)."""
        import json

        out = []
        for entry in self.driver.get_log("performance"):
            msg = json.loads(entry["message"])["message"]
            if msg.get("method") == "Network.requestWillBeSent":
                out.append((msg["params"]["request"]["url"], msg["params"].get("documentURL", "")))
        return out
