"""The study form's structured fields for two JSON options: the feedback questions (FEEDBACK_ROWS rows of key,
text and kind) and the exclusion rules (one number field per rule of analysis.exclusion.RULES, with its meaning
and default as help). Like the pool editor's: the fields win as soon as one of them is edited; otherwise the raw
JSON (kept in a collapsed fieldset, so JSON stays importable and exportable) is saved as it is."""
from __future__ import annotations

import re

from django import forms

from analysis.exclusion import RULES

FEEDBACK_ROWS = 6
FEEDBACK_KINDS = (("yesno", "yes / no"), ("text", "free text"))
KEY_RE = re.compile(r"^[a-z][a-z0-9_]{0,39}$")


def feedback_names(i: int) -> tuple[str, str, str]:
    """The key, text and kind field names of feedback row ``i``."""
    return f"feedback_{i}_key", f"feedback_{i}_text", f"feedback_{i}_kind"


def rule_name(key: str) -> str:
    """The form field of exclusion rule ``key``."""
    return f"rule_{key}"


FEEDBACK_FIELDS = tuple(name for i in range(FEEDBACK_ROWS) for name in feedback_names(i))
RULE_FIELDS = tuple(rule_name(key) for key in RULES)


def declared_fields() -> dict[str, forms.Field]:
    """The structured fields, to declare on the study form (the admin's fieldsets name them)."""
    fields: dict[str, forms.Field] = {}
    for i in range(FEEDBACK_ROWS):
        key, text, kind = feedback_names(i)
        fields[key] = forms.CharField(required=False, max_length=40, label=f"Question {i + 1}: key",
                                      help_text="its column in participants.csv (lower case, digits, _)")
        fields[text] = forms.CharField(required=False, max_length=300, label="text",
                                       widget=forms.TextInput(attrs={"size": 60}))
        fields[kind] = forms.ChoiceField(required=False, choices=FEEDBACK_KINDS, initial="yesno", label="answer")
    for key, (kind, lo, hi, default, meaning) in RULES.items():
        field_class = forms.IntegerField if kind is int else forms.FloatField
        fields[rule_name(key)] = field_class(required=False, min_value=lo, max_value=hi,
                                             label=key.replace("_", " "),
                                             help_text=f"{meaning}; blank: the default, {default:g}")
    return fields


def set_initial(form: forms.Form) -> None:
    """The structured fields' initial values, read from the form's instance's JSON."""
    questions = form.instance.feedback_questions if isinstance(form.instance.feedback_questions, list) else []
    for i, q in enumerate(questions[:FEEDBACK_ROWS]):
        if isinstance(q, dict):
            key, text, kind = feedback_names(i)
            form.initial.setdefault(key, str(q.get("key", "")))
            form.initial.setdefault(text, str(q.get("text", "")))
            form.initial.setdefault(kind, str(q.get("kind", "yesno")))
    rules = form.instance.exclusion_rules if isinstance(form.instance.exclusion_rules, dict) else {}
    for key in RULES:
        if key in rules:
            form.initial.setdefault(rule_name(key), rules[key])


def touched(form: forms.Form, names) -> bool:
    """Whether any of the named fields was changed on the page (then the fields, not the raw JSON, are saved)."""
    return any(name in form.changed_data for name in names)


def feedback_from_fields(form: forms.Form, data: dict) -> list[dict]:
    """The feedback questions the rows say (rows without a key and text skipped); errors go to their fields."""
    out, seen = [], set()
    for i in range(FEEDBACK_ROWS):
        key_name, text_name, kind_name = feedback_names(i)
        key, text = (data.get(key_name) or "").strip(), (data.get(text_name) or "").strip()
        if not key and not text:
            continue
        if not KEY_RE.match(key):
            form.add_error(key_name, "a key: a lower-case letter, then letters, digits or _ (at most 40)")
            continue
        if key in seen:
            form.add_error(key_name, f"the key {key!r} is used twice")
            continue
        if not text:
            form.add_error(text_name, "the question's text")
            continue
        seen.add(key)
        out.append({"key": key, "text": text, "kind": data.get(kind_name) or "yesno"})
    return out


def rules_from_fields(data: dict) -> dict:
    """The exclusion rules the fields give (blank fields left out: their defaults apply)."""
    return {key: data[rule_name(key)] for key in RULES if data.get(rule_name(key)) is not None}
