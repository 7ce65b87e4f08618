"""Shared pytest fixtures: the browsers participants use, driven headless (Chromium and WebKitGTK through
Selenium, Firefox ESR through Marionette), and single-threaded torch."""
from __future__ import annotations

import os
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

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
    """Tests start many participants from one address (127.0.0.1): the start rate limit
    (studyapp.participant.start_throttle) is off unless a test turns it on
    (tests/studyapp/participant/test_start_rate_limit.py)."""
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


WEBKIT_BROWSERS = ("/usr/lib/x86_64-linux-gnu/webkit2gtk-4.1/MiniBrowser",
                   "/usr/lib/x86_64-linux-gnu/webkit2gtk-4.0/MiniBrowser",
                   "/usr/lib/aarch64-linux-gnu/webkit2gtk-4.1/MiniBrowser")
BROWSER_WINDOW = (1366, 900)


@pytest.fixture
def x_display():
    """An X display for browsers that need one (WebKitGTK): the session's DISPLAY (e.g. under xvfb-run), else a
    private Xvfb started here and stopped afterwards. Skips when neither exists."""
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    xvfb = _find("Xvfb")
    if not xvfb:
        pytest.skip("no X display for WebKitGTK: apt-get install xvfb (or run the tests under xvfb-run)")
    proc = subprocess.Popen([xvfb, "-displayfd", "1", "-screen", "0", "1600x1000x24", "-nolisten", "tcp"],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    number = proc.stdout.readline().decode().strip()
    if not number.isdigit():
        proc.kill()
        pytest.skip("Xvfb did not start")
    try:
        yield f":{number}"
    finally:
        proc.terminate()
        proc.wait(timeout=10)


@pytest.fixture
def webkit(x_display, monkeypatch):
    """Safari's engine: WebKitGTK's MiniBrowser driven by Selenium through WebKitWebDriver (Debian
    webkit2gtk-driver), on an X display. Skips with a clear reason when it is not installed."""
    driver_path = _find("WebKitWebDriver")
    browser = next((p for p in WEBKIT_BROWSERS if Path(p).exists()), None)
    if not driver_path or not browser:
        pytest.skip("WebKitGTK not installed: apt-get install webkit2gtk-driver xvfb")
    from selenium import webdriver
    from selenium.webdriver.webkitgtk.options import Options
    from selenium.webdriver.webkitgtk.service import Service

    monkeypatch.setenv("DISPLAY", x_display)
    options = Options()
    options.binary_location = browser
    options.add_argument("--automation")
    driver = webdriver.WebKitGTK(options=options, service=Service(executable_path=driver_path))
    driver.set_window_size(*BROWSER_WINDOW)
    try:
        yield driver
    finally:
        driver.quit()


class MarionetteBrowser:
    """The part of Selenium's WebDriver API the browser tests use (get, current_url, refresh, execute_script,
    quit), on a Marionette client (PyPI marionette-driver). Scripts run in the page's own scope, as Selenium's."""

    def __init__(self, client):
        self.client = client

    def get(self, url: str) -> None:
        self.client.navigate(url)

    @property
    def current_url(self) -> str:
        return self.client.get_url()

    def refresh(self) -> None:
        self.client.refresh()

    def execute_script(self, script: str, *args):
        return self.client.execute_script(script, script_args=list(args), sandbox=None)

    def quit(self) -> None:
        self.client.delete_session()
        self.client.cleanup()


@pytest.fixture
def firefox():
    """Firefox ESR (Debian firefox-esr), headless, driven through Marionette (PyPI marionette-driver: no Linux
    geckodriver comes from the registries). Skips with a clear reason when either is missing."""
    browser = _find("firefox-esr", "firefox")
    if not browser:
        pytest.skip("Firefox not installed: apt-get install firefox-esr")
    try:
        from marionette_driver.marionette import Marionette
    except ImportError:
        pytest.skip("marionette-driver not installed: pip install -r requirements.txt")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    log = Path(tempfile.mkdtemp(prefix="gecko-")) / "gecko.log"     # not the working directory's gecko.log
    client = Marionette(bin=browser, headless=True, port=port, startup_timeout=120, gecko_log=str(log))
    client.start_session()
    client.set_window_rect(width=BROWSER_WINDOW[0], height=BROWSER_WINDOW[1])
    browser_api = MarionetteBrowser(client)
    try:
        yield browser_api
    finally:
        browser_api.quit()
