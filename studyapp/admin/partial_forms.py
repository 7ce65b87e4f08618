"""Model forms that hold only some of their model's fields: one step of the study page (studyapp.admin.study_steps).

The admin builds a step's form with ``fields`` = that step's fields. Three things would go wrong by default, and
:class:`PartialModelForm` handles each:

- declared fields (the pool editor's and the study's structured fields) are added by Django whatever ``fields``
  says; a step's form would then carry, unrendered, the structured fields of other steps, see them posted blank,
  count them as edited and overwrite saved JSON. ``__init__`` drops every declared field ``fields`` does not name.
- a check that reads several fields (a section's pool against its type and options) needs the saved value of a
  field the step does not show: :meth:`value_of` gives the posted value or else the saved one.
- the model's ``clean`` may name a field the step does not show (Django raises ValueError for that): such an
  error becomes an error of the whole form that names the field, so the researcher reads what to fix and where.
"""
from __future__ import annotations

from django import forms
from django.core.exceptions import NON_FIELD_ERRORS, ValidationError


class PartialModelForm(forms.ModelForm):
    """A ModelForm whose ``Meta.fields`` list (the admin's fieldsets) is the whole of its fields."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        listed = self._meta.fields
        if isinstance(listed, (list, tuple)):
            for name in [n for n in self.fields if n in self.declared_fields and n not in listed]:
                del self.fields[name]

    def shows(self, name: str) -> bool:
        """Whether this form has the field ``name`` (a step may leave it out)."""
        return name in self.fields

    def value_of(self, data: dict, name: str):
        """``name``'s cleaned value when the form has the field, else the saved instance's value."""
        return data.get(name) if self.shows(name) else getattr(self.instance, name, None)

    def _update_errors(self, errors):
        """Errors of the model's clean about fields this form lacks become form errors naming the field."""
        if hasattr(errors, "error_dict"):
            kept, moved = {}, []
            for name, messages in errors.error_dict.items():
                if name == NON_FIELD_ERRORS or name in self.fields:
                    kept[name] = messages
                else:
                    label = self._meta.model._meta.get_field(name).verbose_name if name in {
                        f.name for f in self._meta.model._meta.get_fields()} else name
                    moved += [f"{label}: {message}" for error in messages for message in error.messages]
            if moved:
                kept.setdefault(NON_FIELD_ERRORS, []).extend(ValidationError(m) for m in moved)
            errors = ValidationError(kept)
        super()._update_errors(errors)
