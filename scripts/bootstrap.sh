#!/usr/bin/env bash
# Idempotent set-up: system libraries (when root and missing), the virtual environment and the pinned
# requirements. A second run only checks stamps and returns in seconds.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON="${PYTHON:-python3}"
VENV="${VENV:-.venv}"
SYSTEM_PACKAGES=(chromium chromium-driver libegl1 libgl1-mesa-dri)
# Best effort: the other browsers participants use, for the browser tests (tests/studyapp/participant/test_e2e_browsers.py skips a
# browser that is missing): WebKitGTK (Safari's engine) with its WebDriver, GStreamer's H.264 decoder and a virtual
# X display, and Firefox ESR (driven through Marionette, PyPI marionette-driver).
OPTIONAL_PACKAGES=(webkit2gtk-driver gstreamer1.0-libav xvfb firefox-esr)

missing=()
for pkg in "${SYSTEM_PACKAGES[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
if ((${#missing[@]})); then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        echo "==> installing system packages: ${missing[*]}"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}" >/dev/null
    else
        echo "!! missing system packages (${missing[*]}): install them with"
        echo "   sudo apt-get install ${missing[*]}"
        echo "   (rendering needs libegl1 libgl1-mesa-dri; browser tests need chromium chromium-driver)"
    fi
fi

optional=()
for pkg in "${OPTIONAL_PACKAGES[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || optional+=("$pkg")
done
if ((${#optional[@]})) && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "==> installing optional browsers for the browser tests: ${optional[*]}"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${optional[@]}" >/dev/null; } || echo "!! optional browsers not installed (their browser tests skip)"
fi

if [ ! -x "$VENV/bin/python" ]; then
    echo "==> creating virtual environment $VENV"
    "$PYTHON" -m venv "$VENV"
fi

stamp="$VENV/.requirements.sha256"
want="$(sha256sum requirements.txt | cut -d' ' -f1)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    echo "==> installing pinned requirements (torch first: the CPU wheel; this takes a few minutes once)"
    "$VENV/bin/python" -m pip install -q --upgrade pip
    "$VENV/bin/python" -m pip install -q "$(grep -E '^torch==' requirements.txt)"
    "$VENV/bin/python" -m pip install -q -r requirements.txt
    echo "$want" > "$stamp"
fi
