"""The question fieldsets of a clip page (templates/studyapp/item_questions.html), rendered once per distinct
content and kept in a bounded per-process cache.

Rendering the radio/checkbox loops was most of a clip page's template time, yet a page's questions depend only on
their wording, choices and kinds in the active language: thousands of participants see the same few dozen
fragments. The cache key is that content itself (every text, value and label shown, and the language), so an edited
section or another language can never get a stale fragment. A page re-shown with the participant's selections (an
answer refused with an error) is rendered without the cache.
"""
from __future__ import annotations

import threading
from collections import OrderedDict

from django.template.loader import render_to_string
from django.utils.safestring import SafeString
from django.utils.translation import get_language

TEMPLATE = "studyapp/item_questions.html"
MAX_ENTRIES = 2048          # gesture pages differ by their four drawn options; a fragment is a few kB

_cache: OrderedDict[tuple, SafeString] = OrderedDict()
_lock = threading.Lock()


def questions_html(fields: list[dict]) -> SafeString:
    """The fieldsets of `fields` ([{"q": Question, "selected": [posted values]}]) as safe HTML."""
    if any(f["selected"] for f in fields):
        return render_to_string(TEMPLATE, {"fields": fields})
    key = (get_language(), tuple((q.key, q.text, q.kind, tuple(q.choices), q.help) for q in (f["q"] for f in fields)))
    with _lock:
        html = _cache.get(key)
        if html is not None:
            _cache.move_to_end(key)
            return html
    html = render_to_string(TEMPLATE, {"fields": fields})
    with _lock:
        _cache[key] = html
        while len(_cache) > MAX_ENTRIES:
            _cache.popitem(last=False)
    return html


def clear() -> None:
    """Forget every cached fragment (tests that change templates or translations at run time)."""
    with _lock:
        _cache.clear()
