"""The browser fixtures skip with the reason, and what to install, when a browser is missing."""
from __future__ import annotations

import conftest
import pytest


@pytest.mark.parametrize("fixture, reason", [
    ("chromium", "apt-get install chromium chromium-driver"),
    ("webkit", "apt-get install xvfb"),                     # no display and no Xvfb: said first
    ("firefox", "apt-get install firefox-esr"),
])
def test_missing_browser_skips_with_what_to_install(fixture, reason, request, monkeypatch):
    monkeypatch.setattr(conftest, "_find", lambda *names: None)
    monkeypatch.delenv("DISPLAY", raising=False)
    with pytest.raises(pytest.skip.Exception, match=reason):
        request.getfixturevalue(fixture)


def test_webkit_without_its_driver_says_so(request, monkeypatch):
    monkeypatch.setattr(conftest, "_find", lambda *names: None)
    monkeypatch.setenv("DISPLAY", ":99")                   # a display, but no WebKitWebDriver
    with pytest.raises(pytest.skip.Exception, match="apt-get install webkit2gtk-driver"):
        request.getfixturevalue("webkit")
