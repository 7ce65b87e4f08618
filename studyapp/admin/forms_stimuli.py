"""The admin's stimulus-set form, written from the generator registry (generation.plans.generators): a generator,
its conditions one per line, variants per condition, render settings; it turns into a plan with
generation.plans.stimulus_set and refuses what the plan schema refuses, next to the field at fault."""
from __future__ import annotations

import re

import yaml
from django import forms

from generation.plans.generators import registered
from generation.plans.schema import builtin_plans
from generation.plans.stimulus_set import StimulusSet, StimulusSetError, build_plan
from generation.render.settings import BODIES, CAMERAS, RenderSettings
from protocol.vocabulary import SECTION_TYPES

DEFAULTS = RenderSettings()
RENDER_FIELDS = ("width", "height", "fps", "duration_s", "camera", "body")


def generator_choices() -> list[tuple[str, str]]:
    """(name, "name: summary") of every registered generator, the form's generator choices."""
    return [(spec.name, f"{spec.name.replace('_', ' ')}: {spec.summary}") for spec in registered()]


class StimulusSetForm(forms.Form):
    """The stimuli page's "new stimulus set" form: a plan name, a generator and its conditions, variants and first seed,
    fields every clip shares, the render settings (size in px, fps, duration in s, camera, body), the intended section
    types and the fallback switch. A valid form holds the built plan in ``plan_data`` and ``plan``."""

    name = forms.SlugField(max_length=60, help_text="The plan's name: its clips are catalogued under it (pool "
                                                    "filter <code>plan</code>). Lower-case letters, digits, - and _.")
    description = forms.CharField(required=False, max_length=300)
    generator = forms.ChoiceField(choices=generator_choices)
    conditions = forms.CharField(
        required=False, widget=forms.Textarea(attrs={"rows": 6, "cols": 60}),
        help_text="One condition per line; the table below says what each generator reads. Lines starting with # "
                  "are ignored.")
    variants = forms.IntegerField(min_value=1, max_value=50, initial=1,
                                  help_text="Clips per condition, each with its own seed (walks: its own path).")
    seed = forms.IntegerField(min_value=0, max_value=2**31 - 1000, initial=1, help_text="The first seed.")
    shared = forms.CharField(
        required=False, label="Fields of every clip", widget=forms.Textarea(attrs={"rows": 2, "cols": 60}),
        help_text="Optional YAML mapping of generator fields every clip gets, e.g. "
                  "<code>{weights: real}</code> or <code>{gender: female, handedness: right}</code>.")
    width = forms.IntegerField(min_value=16, max_value=4096, initial=DEFAULTS.width)
    height = forms.IntegerField(min_value=16, max_value=4096, initial=DEFAULTS.height)
    fps = forms.FloatField(min_value=1, max_value=240, initial=DEFAULTS.fps)
    duration_s = forms.FloatField(min_value=0.1, max_value=600, initial=DEFAULTS.duration_s,
                                  label="Duration (s)")
    camera = forms.ChoiceField(choices=[(c, c) for c in CAMERAS], initial=DEFAULTS.camera)
    body = forms.ChoiceField(choices=[(b, b) for b in BODIES], initial=DEFAULTS.body)
    sections = forms.MultipleChoiceField(
        required=False, choices=[(s, s.replace("_", " ")) for s in SECTION_TYPES],
        widget=forms.CheckboxSelectMultiple, help_text="Which sections the clips are meant for (a hint for pools).")
    fallback = forms.BooleanField(
        required=False, initial=True, label="Use the fallback generator while this one is unavailable",
        help_text="e.g. the procedural walk while the gait network's weights are missing; recorded per clip.")

    def clean_shared(self) -> dict:
        """The "fields of every clip" box as a dict (blank: {}); refused unless it is a YAML mapping."""
        text = self.cleaned_data.get("shared", "").strip()
        if not text:
            return {}
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise forms.ValidationError(f"not YAML: {exc}") from None
        if not isinstance(data, dict):
            raise forms.ValidationError("expected a mapping of field: value")
        return data

    def clean_name(self) -> str:
        """The plan name in lower case; refused when a built-in plan has it."""
        name = self.cleaned_data["name"].lower()
        if name in builtin_plans():
            raise forms.ValidationError(f"{name!r} is a built-in plan: render it from the list of built-in plans, "
                                        "or pick another name")
        return name

    def clean(self):
        """Build the plan from the fields (generation.plans.stimulus_set.build_plan); what the plan schema refuses
        becomes an error on the field at fault (a render setting, the generator's field) or on the form."""
        data = super().clean()
        if self.errors:
            return data
        stimulus_set = StimulusSet(
            name=data["name"], generator=data["generator"], conditions=data["conditions"].splitlines(),
            variants=data["variants"], seed=data["seed"], shared=data["shared"],
            render={"width": data["width"], "height": data["height"], "fps": data["fps"],
                    "duration_s": data["duration_s"], "camera": data["camera"], "body": data["body"]},
            sections=list(data["sections"]), fallback=data["fallback"], description=data["description"])
        try:
            self.plan_data, self.plan = build_plan(stimulus_set)
        except StimulusSetError as exc:
            named = re.search(r"field '(\w+)'", str(exc))
            if named and named.group(1) in RENDER_FIELDS:        # e.g. a walk shorter than its generator allows
                target = named.group(1)
            else:
                target = exc.field if exc.field in self.fields and exc.field != "render" else None
            self.add_error(target, str(exc))
        return data
