"""The researcher's forms outside the admin: create a study from a preset, clone a study, share a preview link."""
from __future__ import annotations

from django import forms

from ..models import Study
from .presets import preset_choices


class PresetStudyForm(forms.Form):
    """The "New study from preset" page's form: a preset, the new study's slug (not yet taken) and an optional title."""

    preset = forms.ChoiceField(choices=preset_choices)
    slug = forms.SlugField(max_length=80, help_text="Used in the participant URL /s/<slug>/")
    title = forms.CharField(max_length=200, required=False, help_text="Leave blank for the preset's title")

    def clean_slug(self):
        """The slug, refused when another study already has it."""
        slug = self.cleaned_data["slug"]
        if Study.objects.filter(slug=slug).exists():
            raise forms.ValidationError(f"A study with slug '{slug}' already exists.")
        return slug


class CloneStudyForm(forms.Form):
    """The clone page's form: the copy's slug (not yet taken) and title."""

    slug = forms.SlugField(max_length=80, help_text="The copy's participant URL /s/<slug>/")
    title = forms.CharField(max_length=200)

    def clean_slug(self):
        """The slug, refused when another study already has it."""
        slug = self.cleaned_data["slug"]
        if Study.objects.filter(slug=slug).exists():
            raise forms.ValidationError(f"A study with slug '{slug}' already exists.")
        return slug


class SharePreviewForm(forms.Form):
    """The progress page's "share a preview" form: how many days (1 to 90) the signed link stays valid."""

    days = forms.IntegerField(min_value=1, max_value=90, initial=14, label="Valid for (days)")
