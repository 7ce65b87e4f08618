"""Shared pytest fixtures: a headless Chromium driven by Selenium, and single-threaded torch."""
from __future__ import annotations

import shutil
import tempfile

import pytest

from generation.render.offscreen import prepare_render_process

prepare_render_process()

CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-quic",
    "--disable-dev-shm-usage",
    "--autoplay-policy=no-user-gesture-required",
    "--window-size=1280,900",
)


def _find(*names: str) -> str | None:
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(autouse=True, scope="session")
def _single_threaded_torch():
    """Tests run on 2 shared cores: keep torch from oversubscribing them."""
    try:
        import torch
    except ImportError:  # pragma: no cover - torch is a requirement
        return
    torch.set_num_threads(1)


@pytest.fixture(autouse=True)
def _start_rate_limit_off(settings):
    """Tests start many participants from one address (127.0.0.1): the start rate limit (studyapp.start_throttle)
    is off unless a test turns it on (tests/test_start_rate_limit.py)."""
    settings.START_RATE_BURST = 0


@pytest.fixture
def chromium():
    """A Selenium WebDriver on Debian's headless Chromium (/usr/bin/chromium + chromedriver).

    Skips with a clear reason when the browser is not installed (`.ci/run` and `setup.sh` install it).
    """
    browser = _find("chromium", "chromium-browser")
    driver_path = _find("chromedriver")
    if not browser or not driver_path:
        pytest.skip("headless Chromium not installed: apt-get install chromium chromium-driver")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = browser
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    profile = tempfile.mkdtemp(prefix="chromium-profile-")
    options.add_argument(f"--user-data-dir={profile}")
    driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
    driver.set_page_load_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)
