"""Test and benchmark helpers: a small SYNTHETIC clip catalogue covering every section pool.

The clips are placeholders (tiny dummy files, or one real 1-second MP4 when given), marked
metadata["synthetic"] = True; they are not rendered motion and never presented as such.
"""
from __future__ import annotations

import hashlib
import itertools
import time
from pathlib import Path

import imageio_ffmpeg
import numpy as np
from django import forms

from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_EMOTIONS, NEUTRAL_THEME, THEMES

from .admin.forms import SectionForm
from .data.catalogue import upsert_clips

GAIT_VECTORS = [   # in protocol.vocabulary.GAIT_EMOTIONS order; GAIT_VECTORS[3] is pure neutral
    (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1), (0.5, 0, 0, 0.5), (0, 0.5, 0.5, 0),
    (0.6, 0.1, 0, 0.3), (0, 0.7, 0, 0.3), (0.25, 0.25, 0.25, 0.25), (0, 0, 0.8, 0.2)]


def write_media(media_root: Path, payload: bytes, suffix: str = ".mp4") -> str:
    """Write payload under media_root/clips/<sha1>.<suffix> (content-hash name, like the renderer). Returns the
    path relative to media_root."""
    name = hashlib.sha1(payload).hexdigest()[:16] + suffix
    path = Path(media_root) / "clips" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        path.write_bytes(payload)
    return f"clips/{name}"


def tiny_mp4(path: Path, seconds: float = 1.0, fps: int = 10, size: int = 64, shade: int = 0) -> Path:
    """A real H.264 MP4 (yuv420p, faststart) of a moving grey square, via imageio-ffmpeg."""

    path.parent.mkdir(parents=True, exist_ok=True)
    writer = imageio_ffmpeg.write_frames(str(path), (size, size), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
                                         output_params=["-movflags", "+faststart"], macro_block_size=16)
    writer.send(None)
    for i in range(int(seconds * fps)):
        frame = np.full((size, size, 3), 30 + shade % 60, dtype=np.uint8)
        x = (i * 5) % (size - 16)
        frame[24:40, x:x + 16] = 220
        writer.send(frame.tobytes())
    writer.close()
    return path


def wide_clip(path: Path, seconds: float = 1.0, fps: int = 10, size: tuple[int, int] = (320, 180),
              codec: str = "libx264") -> Path:
    """A SYNTHETIC 16:9 test clip, the shape of the rendered ones: a light figure-sized bar walking over grey.
    codec: libx264 (an MP4: yuv420p, faststart) or libvpx-vp9 (a WebM)."""
    w, h = size
    path.parent.mkdir(parents=True, exist_ok=True)
    extra = ["-movflags", "+faststart"] if codec == "libx264" else ["-b:v", "200k", "-deadline", "realtime"]
    writer = imageio_ffmpeg.write_frames(str(path), (w, h), fps=fps, codec=codec, pix_fmt_out="yuv420p",
                                         output_params=extra, macro_block_size=4)
    writer.send(None)
    for i in range(int(seconds * fps)):
        frame = np.full((h, w, 3), 60, dtype=np.uint8)
        frame[int(h * 0.85):, :] = 90                                      # floor
        x = int((0.1 + 0.8 * i / max(seconds * fps - 1, 1)) * (w - w // 16))
        frame[int(h * 0.25):int(h * 0.85), x:x + w // 16] = 220            # the "figure"
        writer.send(frame.tobytes())
    writer.close()
    return path


def make_catalogue(media_root: Path, video_bytes: bytes | None = None, duration_s: float | None = None,
                   n_gait: int = 10, n_transition: int = 6, n_gait_source: int = 4, n_gesture: int = 12,
                   gesture_video_bytes: bytes | None = None, webm_bytes: bytes | None = None) -> int:
    """Insert a synthetic catalogue: generated/source gaits, transitions, gestures (each generated gesture made from
    a source gesture), one neutral RBF input walk and RBF theme clips with positive and negative weights.
    webm_bytes: a WebM every clip gets beside its MP4 (none when None)."""
    records = []

    def media(tag: str, modality: str) -> str:
        payload = gesture_video_bytes if modality == "gesture" and gesture_video_bytes is not None else video_bytes
        return write_media(media_root, payload if payload is not None else f"dummy {tag}".encode())

    def base(clip_id: str, modality: str, origin: str, **extra) -> dict:
        rec = {"clip_id": clip_id, "modality": modality, "origin": origin, "video": media(clip_id, modality),
               "webm": write_media(media_root, webm_bytes, ".webm") if webm_bytes is not None else "",
               "poster": "", "plan": "test", "loop": False, "duration_s": duration_s,
               "metadata": {"synthetic": True, "note": "test placeholder, not rendered motion"}}
        rec.update(extra)
        return rec

    def gait(vector, prefix: str = "") -> dict:
        return {f"{prefix}{e}": v for e, v in zip(GAIT_EMOTIONS, vector, strict=True)}

    vectors = itertools.cycle(GAIT_VECTORS)
    for i in range(n_gait):
        records.append(base(f"gait_gen_{i:02d}", "gait", "generated", **gait(next(vectors))))
    for i in range(n_gait_source):
        records.append(base(f"gait_src_{i:02d}", "gait", "source", **gait(GAIT_VECTORS[3])))
    for i in range(n_transition):
        records.append(base(f"gait_tr_{i:02d}", "gait", "generated", **gait(GAIT_VECTORS[i % 4]),
                            **gait(GAIT_VECTORS[(i + 1) % 4], "final_")))
    for i in range(n_gesture):
        label = GESTURE_EMOTIONS[i % len(GESTURE_EMOTIONS)]
        records.append(base(f"gest_src_{i:02d}", "gesture", "source", emotion_label=label, sections="naturalness"))
        records.append(base(f"gest_gen_{i:02d}", "gesture", "generated", emotion_label=label,
                            source_clip_id=f"gest_src_{i:02d}", valence=0.5, arousal=0.5, dominance=0.5,
                            sections="gesture_emotion,naturalness"))     # the plans' section hints
    records.append(base("rbf_neutral", "gait", "source", theme=NEUTRAL_THEME, weight=0.0,
                        n_features=0))
    for theme in THEMES:
        for w in (0.4, 1.0):
            records.append(base(f"rbf_{theme}_{w}", "gait", "generated", theme=theme, weight=w, n_features=10))
        records.append(base(f"rbf_{theme}_inv", "gait", "generated", theme=theme, weight=-0.7, n_features=10))
    return upsert_clips(records)


def admin_form_data(response) -> dict[str, str]:
    """The POST data an admin change (or add) page would submit unchanged: its main form and every inline
    formset with its management form, from the page's template context (Django test client response)."""

    def fields(form) -> dict[str, str | list[str]]:
        data = {}
        for bound in form:
            value = bound.value()
            if isinstance(bound.field, forms.BooleanField):
                if value:
                    data[bound.html_name] = "on"
                continue
            if isinstance(bound.field, forms.ModelMultipleChoiceField):      # owners, collaborators
                data[bound.html_name] = [str(getattr(v, "pk", v)) for v in value or []]
                continue
            data[bound.html_name] = "" if value is None else str(value)
        return data

    data = fields(response.context["adminform"].form)
    for inline in response.context["inline_admin_formsets"]:
        formset = inline.formset
        data.update(fields(formset.management_form))
        for form in formset.forms:
            data.update(fields(form))
    return data


def wait_for(driver, condition, timeout: float = 20.0, what: str = "condition"):
    """Poll ``condition(driver)`` (a selenium WebDriver) every 0.1 s until it returns something truthy, and return
    that; AssertionError naming ``what`` and the page after ``timeout`` seconds. Exceptions while the page is
    changing (element not there yet, stale element) count as "not yet"."""

    end = time.time() + timeout
    while time.time() < end:
        try:
            value = condition(driver)
            if value:
                return value
        except Exception:     # element not there yet / stale while navigating
            pass
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}; at {driver.current_url}")


def consent_and_demographics(driver) -> None:
    """In a browser (selenium WebDriver) on a study's consent page: consent, start, answer the demographics page
    with its first choices, and wait for the first clip page."""
    from selenium.webdriver.common.by import By  # optional: selenium is installed for the browser tests only

    driver.find_element(By.CSS_SELECTOR, "label.check").click()
    driver.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait_for(driver, lambda d: "/about-you/" in d.current_url, what="demographics page")
    for name in ("gender", "age_group"):
        driver.find_element(By.CSS_SELECTOR, f"input[name={name}]").find_element(By.XPATH, "..").click()
    driver.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait_for(driver, lambda d: "/clip/1/" in d.current_url, what="first clip")


def section_form_errors(section) -> dict[str, list[str]]:
    """The errors of the admin's section form when ``section`` is posted as it stands in memory (its fields
    unchanged, its pool and options as raw JSON): the checks that need the catalogue or norms run there, not in the
    model layer."""
    data = {}
    for bound in SectionForm(instance=section):
        value = bound.value()
        if isinstance(bound.field, forms.BooleanField):
            if value:
                data[bound.html_name] = "on"
        elif isinstance(value, (list, tuple)):
            data[bound.html_name] = [str(v) for v in value]
        else:
            data[bound.html_name] = "" if value is None else str(value)
    form = SectionForm(data=data, instance=section)
    form.is_valid()
    return dict(form.errors)
