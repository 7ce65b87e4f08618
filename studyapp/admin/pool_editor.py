"""The admin's pool editor: form fields <-> a section's ``pool`` and ``options`` JSON (the language of
protocol.pools), and the rule that decides which of the two a save uses.

Every *spec* below owns some keys of the JSON and one or more form fields:

- ``read(json) -> (field values, the json without the keys it took)``
- ``write(field values) -> the json fragment those values mean``
- ``owner(message) -> the field a protocol.pools message is about`` (messages name their key, e.g. ``'weight__gte'``)

``pool_to_fields`` / ``fields_to_pool`` (and ``options_to_fields`` / ``fields_to_options``) run every spec. Keys no
spec can show (``plan__startswith``, ``happy__gt``, a key added to the pool language later) come back as the
*leftover* and are kept as they are whenever the fields are written back.

Round trips: fields -> JSON -> fields gives the same field values; JSON -> fields -> JSON gives an equivalent pool in
canonical spelling (``theme__in`` becomes a ``theme`` list, equal ``n_features__gte``/``__lte`` become
``n_features``, lists follow the protocol's order).

Fields or raw JSON (``resolve_section_json``): the raw JSON (``pool`` / ``options``) wins only when every structured
field of its group was left as the page showed it (Django's ``changed_data``: value differs from the initial one,
which is read from the saved JSON). Once a structured field of the group was edited, the fields win for the keys
they own and the raw JSON contributes only its leftover keys.
"""
from __future__ import annotations

from django import forms
from django.utils.html import format_html, format_html_join

from protocol.norming import DEFAULT_RATINGS_PER_CLIP, NORMING_OPTION
from protocol.pools import (
    COMMON_OPTIONS,
    DEFAULT_GESTURE_OPTIONS,
    DEFAULT_PLAYER_CONTROLS,
    INCLUDE_FLAGGED,
    KEEP_ADVISORY,
    MAX_RATINGS_PER_CLIP,
    MAX_REPLAYS_LIMIT,
    OBSERVER_ADVISORY,
    PLAYER_CONTROLS,
    SUB_POOLS,
    validate_section,
)
from protocol.section_types import find_section_type, registered
from protocol.section_types.pages import DEFAULT_WAIT_SECONDS, MAX_WAIT_SECONDS, WAIT_OPTION
from protocol.vocabulary import (
    CLIP_MODALITIES,
    CLIP_THEMES,
    GESTURE_EMOTIONS,
    NATURALNESS,
    ORIGINS,
    QA_ADVISORY_CHECKS,
    answer_values,
)

ANY = ""
TRISTATE = [(ANY, "any"), ("yes", "yes"), ("no", "no")]
SIGNS = {"positive": ("__gt", "> 0 (styled towards the theme)"), "negative": ("__lt", "< 0 (inverted, opposite theme)"),
         "zero": ("", "= 0 (the unstyled input walk)")}
"""weight sign choice -> (lookup compared with 0, label)."""
N_FEATURES_MAX = 10_000
WEIGHT_LIMIT = 1e6
POOL_PREFIX, OPTIONS_PREFIX = "pool_", "opt_"


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def split_choices(value) -> list[str]:
    """A multiple choice as a list: None, a comma-separated string or a list of such strings."""
    if value is None:
        return []
    items = [value] if isinstance(value, str) else list(value)
    return [part.strip() for item in items for part in str(item).split(",") if part.strip()]


class ChoiceListWidget(forms.CheckboxSelectMultiple):
    """Check boxes whose value may also be given as one comma-separated string (``gait,gesture``)."""

    def format_value(self, value):
        """The ticked values, from a list or one comma-separated string."""
        return super().format_value(split_choices(value))

    def value_from_datadict(self, data, files, name):
        """The posted values as a list, from several check boxes or one comma-separated string."""
        return split_choices(data.getlist(name) if hasattr(data, "getlist") else data.get(name))


class ChoiceListField(forms.MultipleChoiceField):
    """Several values of one vocabulary; none ticked means any. Its text value is comma-separated, so a page's
    values can be posted back as one string (studyapp.testing.admin_form_data) or as several check boxes."""

    widget = ChoiceListWidget

    def __init__(self, vocabulary, **kwargs):
        super().__init__(choices=[(v, v) for v in vocabulary], required=False, **kwargs)
        self.vocabulary = tuple(vocabulary)

    def prepare_value(self, value):
        """The value as one comma-separated string, the form the page posts back."""
        return ",".join(split_choices(value))

    def to_python(self, value):
        """The posted value as a list of strings."""
        return split_choices(value)

    def clean(self, value):
        """The chosen values in the vocabulary's order, each once; an unknown value is a field error."""
        chosen = set(super().clean(value))
        return [v for v in self.vocabulary if v in chosen]

    def has_changed(self, initial, data):
        """Whether the set of values differs from the initial one (order and spelling, list or string, do not count)."""
        return set(split_choices(initial)) != set(split_choices(data))


class DatalistInput(forms.TextInput):
    """A text box with suggestions (an HTML datalist), e.g. the plans in the catalogue."""

    def __init__(self, suggestions=(), attrs=None):
        super().__init__(attrs)
        self.suggestions = list(suggestions)

    def render(self, name, value, attrs=None, renderer=None):
        """The text box with its ``<datalist>`` of suggestions, linked by the box's id."""
        list_id = f"{(attrs or {}).get('id', name)}_suggestions"
        box = super().render(name, value, {**(attrs or {}), "list": list_id}, renderer)
        options = format_html_join("", '<option value="{}">', ((s,) for s in self.suggestions))
        return format_html('{}<datalist id="{}">{}</datalist>', box, list_id, options)


# ---- specs ----------------------------------------------------------------------------------------------------

class ChoiceSpec:
    """``key``: one value (``"gait"``) or a list (``["sad", "tired"]``, also read from ``key__in``) of a vocabulary.

    Also the base of every spec below: ``form_fields``, ``read``, ``write``, ``owner`` and ``check`` (problems
    between its own fields, e.g. a range upside down: field -> message)."""

    def __init__(self, field: str, key: str, vocabulary, label: str, help_text: str = "none ticked: any"):
        self.field, self.key, self.vocabulary, self.label, self.help = field, key, tuple(vocabulary), label, help_text

    def form_fields(self) -> dict[str, forms.Field]:
        """The spec's form fields by name: here one check-box list of the vocabulary."""
        return {self.field: ChoiceListField(self.vocabulary, label=self.label, help_text=self.help)}

    def _values(self, value) -> list[str] | None:
        items = [value] if isinstance(value, str) else value
        if isinstance(items, list) and items and all(isinstance(v, str) and v in self.vocabulary for v in items) \
                and len(set(items)) == len(items):
            return [v for v in self.vocabulary if v in items]
        return None

    def read(self, data: dict) -> tuple[dict, dict]:
        """(field values, the data without the keys taken): ``key`` or a list in ``key__in`` whose values are all of the
        vocabulary, each once; anything else stays in the leftover."""
        for key in (self.key, f"{self.key}__in"):
            if key.endswith("__in") and not isinstance(data.get(key), list):
                continue
            if key in data and (values := self._values(data[key])) is not None:
                return {self.field: values}, {k: v for k, v in data.items() if k != key}
        return {}, data

    def write(self, values: dict) -> dict:
        """The JSON fragment of the ticked values: one value as a string, several as a list in the vocabulary's order,
        none as nothing."""
        chosen = [v for v in self.vocabulary if v in (values.get(self.field) or [])]
        if not chosen:
            return {}
        return {self.key: chosen[0] if len(chosen) == 1 else chosen}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """The form field of an error about these JSON keys (protocol.pools.SectionError.keys), or None."""
        return self.field if self.key in keys or f"{self.key}__in" in keys else None

    def check(self, values: dict) -> dict[str, str]:
        """Problems between the spec's own fields (field -> message); none for a single field."""
        return {}


class TextListSpec(ChoiceSpec):
    """``key``: free text, several separated by commas in the box (``"demo, test"`` -> ``["demo", "test"]``)."""

    def __init__(self, field: str, key: str, label: str, help_text: str, suggestions=()):
        super().__init__(field, key, (), label, help_text)
        self.suggestions = tuple(suggestions)

    def form_fields(self) -> dict[str, forms.Field]:
        """One text box with the suggestions as a datalist."""
        return {self.field: forms.CharField(required=False, max_length=1000, label=self.label, help_text=self.help,
                                            widget=DatalistInput(self.suggestions))}

    def _values(self, value) -> str | None:
        items = [value] if isinstance(value, str) else value
        if isinstance(items, list) and items and all(isinstance(v, str) and v.strip() == v and v and "," not in v
                                                     for v in items) and len(set(items)) == len(items):
            return ", ".join(items)
        return None

    def write(self, values: dict) -> dict:
        """The comma-separated words as ``key``: one as a string, several as a list (duplicates dropped), none as
        nothing."""
        chosen = list(dict.fromkeys(split_choices(values.get(self.field) or "")))
        if not chosen:
            return {}
        return {self.key: chosen[0] if len(chosen) == 1 else chosen}


class TristateSpec(ChoiceSpec):
    """A boolean shorthand (``transition``, ``rbf``): yes, no or any."""

    def form_fields(self) -> dict[str, forms.Field]:
        """One any / yes / no drop-down."""
        return {self.field: forms.ChoiceField(choices=TRISTATE, required=False, label=self.label,
                                              help_text=self.help)}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``key`` when it is a boolean: yes for true, no for false."""
        if isinstance(data.get(self.key), bool):
            return {self.field: "yes" if data[self.key] else "no"}, {k: v for k, v in data.items() if k != self.key}
        return {}, data

    def write(self, values: dict) -> dict:
        """``key: true`` or ``false`` for yes or no; nothing for any."""
        value = values.get(self.field) or ANY
        return {} if value == ANY else {self.key: value == "yes"}


class SignSpec(ChoiceSpec):
    """``weight`` compared with 0: ``weight__gt: 0``, ``weight__lt: 0`` or ``weight: 0``."""

    def form_fields(self) -> dict[str, forms.Field]:
        """One drop-down of the signs (any, positive, negative, zero)."""
        choices = [(ANY, "any"), *((name, label) for name, (_, label) in SIGNS.items())]
        return {self.field: forms.ChoiceField(choices=choices, required=False, label=self.label,
                                              help_text=self.help)}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes the first of ``key__gt``, ``key__lt`` or ``key`` that compares with exactly 0."""
        for name, (lookup, _) in SIGNS.items():
            key = self.key + lookup
            if _is_number(data.get(key)) and data[key] == 0:
                return {self.field: name}, {k: v for k, v in data.items() if k != key}
        return {}, data

    def write(self, values: dict) -> dict:
        """The sign's comparison with 0 (e.g. ``weight__gt: 0``); nothing for any."""
        name = values.get(self.field) or ANY
        return {} if name == ANY else {self.key + SIGNS[name][0]: 0}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """The field, for an error about any of the sign's keys."""
        return self.field if any(self.key + lookup in keys for lookup, _ in SIGNS.values()) else None


class RangeSpec(ChoiceSpec):
    """An inclusive range of a number column: ``key__gte`` and ``key__lte`` (``key`` itself when both are equal and
    ``exact`` is set). Two form fields, ``<field>_min`` and ``<field>_max``; either may be blank."""

    def __init__(self, field: str, key: str, label: str, help_text: str, integer: bool, exact: bool):
        super().__init__(field, key, (), label, help_text)
        self.integer, self.exact = integer, exact
        self.low, self.high = f"{field}_min", f"{field}_max"

    def form_fields(self) -> dict[str, forms.Field]:
        """The "from" and "to" fields: whole numbers 0 to N_FEATURES_MAX, or numbers within +-WEIGHT_LIMIT."""
        def make(label):
            if self.integer:
                return forms.IntegerField(required=False, min_value=0, max_value=N_FEATURES_MAX, label=label,
                                          help_text=self.help)
            return forms.FloatField(required=False, min_value=-WEIGHT_LIMIT, max_value=WEIGHT_LIMIT, label=label,
                                    help_text=self.help)
        return {self.low: make(f"{self.label} from"), self.high: make(f"{self.label} to")}

    def _ok(self, value) -> bool:
        return _is_int(value) if self.integer else _is_number(value)

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``key__gte`` and ``key__lte`` (or an exact ``key`` alone, as both ends) when they are numbers of the
        right kind."""
        gte, lte, values = f"{self.key}__gte", f"{self.key}__lte", {}
        if self.exact and self._ok(data.get(self.key)) and gte not in data and lte not in data:
            values = {self.low: data[self.key], self.high: data[self.key]}
            taken = {self.key}
        else:
            taken = {k for k in (gte, lte) if self._ok(data.get(k))}
            values = {field: data[k] for field, k in ((self.low, gte), (self.high, lte)) if k in taken}
        return values, {k: v for k, v in data.items() if k not in taken}

    def write(self, values: dict) -> dict:
        """The range as ``key__gte`` / ``key__lte`` (blank ends left out), or ``key`` when exact and both ends are
        equal."""
        low, high = values.get(self.low), values.get(self.high)
        if self.exact and low is not None and low == high:
            return {self.key: low}
        out = {f"{self.key}__gte": low, f"{self.key}__lte": high}
        return {k: v for k, v in out.items() if v is not None}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """"to" for an error about ``key__lte``, "from" for ``key__gte`` or ``key``."""
        if f"{self.key}__lte" in keys:
            return self.high
        return self.low if f"{self.key}__gte" in keys or self.key in keys else None

    def check(self, values: dict) -> dict[str, str]:
        """An error on "to" when the range is upside down (from > to)."""
        low, high = values.get(self.low), values.get(self.high)
        if low is not None and high is not None and low > high:
            return {self.high: f"{high:g} is below {self.label.lower()} from ({low:g})"}
        return {}


class FlagSpec(ChoiceSpec):
    """A switch that only means something when on (``include_flagged: true``, ``practice: true``): a check box."""

    def form_fields(self) -> dict[str, forms.Field]:
        """One check box."""
        return {self.field: forms.BooleanField(required=False, label=self.label, help_text=self.help)}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``key`` only when it is exactly true (false is the default and stays in the leftover)."""
        if data.get(self.key) is True:
            return {self.field: True}, {k: v for k, v in data.items() if k != self.key}
        return {}, data

    def write(self, values: dict) -> dict:
        """``key: true`` when ticked, nothing otherwise."""
        return {self.key: True} if values.get(self.field) else {}


class SelectSpec(ChoiceSpec):
    """One value of a vocabulary (the player's ``controls``): a drop-down whose blank choice leaves the key out
    (the section then gets ``default``)."""

    def __init__(self, field: str, key: str, vocabulary, label: str, help_text: str, default: str):
        super().__init__(field, key, vocabulary, label, help_text)
        self.default = default

    def form_fields(self) -> dict[str, forms.Field]:
        """One drop-down of the vocabulary whose blank choice names the default."""
        choices = [("", f"default ({self.default})"), *((v, v) for v in self.vocabulary)]
        return {self.field: forms.ChoiceField(choices=choices, required=False, label=self.label,
                                              help_text=self.help)}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``key`` when it is one value of the vocabulary."""
        if isinstance(data.get(self.key), str) and data[self.key] in self.vocabulary:
            return {self.field: data[self.key]}, {k: v for k, v in data.items() if k != self.key}
        return {}, data

    def write(self, values: dict) -> dict:
        """``key: value``, or nothing for the blank (default) choice."""
        value = values.get(self.field)
        return {self.key: value} if value else {}


class SubPoolSpec(ChoiceSpec):
    """A naturalness sub-pool (``generated`` / ``source``): the inner specs applied to ``pool[name]``."""

    def __init__(self, name: str, inner: list[ChoiceSpec]):
        super().__init__(f"{POOL_PREFIX}{name}", name, (), name)
        self.inner = inner

    def form_fields(self) -> dict[str, forms.Field]:
        """The inner specs' fields, all on the page."""
        return {name: field for spec in self.inner for name, field in spec.form_fields().items()}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Reads ``pool[name]`` with the inner specs; the sub-pool's leftover keys stay under its name in the
        leftover."""
        sub = data.get(self.key)
        if not isinstance(sub, dict) or not sub:
            return {}, data
        values, rest = read_specs(self.inner, sub)
        remaining = {k: v for k, v in data.items() if k != self.key}
        return values, ({**remaining, self.key: rest} if rest else remaining)

    def write(self, values: dict) -> dict:
        """``{name: {...}}`` of the inner specs' values, nothing when they are all blank."""
        sub = write_specs(self.inner, values)
        return {self.key: sub} if sub else {}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """The inner field of an error about ``name.<key>``, or None."""
        inner = tuple(k.removeprefix(f"{self.key}.") for k in keys if k.startswith(f"{self.key}."))
        return next((field for spec in self.inner if (field := spec.owner(inner))), None) if inner else None

    def check(self, values: dict) -> dict[str, str]:
        """The inner specs' problems, together."""
        return {k: v for spec in self.inner for k, v in spec.check(values).items()}


class AnchorsSpec(ChoiceSpec):
    """Naturalness ``anchors``: a label per scale value (``{"1": "not natural at all", "5": "very natural"}``)."""

    def __init__(self, field: str):
        super().__init__(field, "anchors", answer_values(NATURALNESS), "Anchor")

    def form_fields(self) -> dict[str, forms.Field]:
        """One text box per value of the naturalness scale, ``<field>_<value>``."""
        return {f"{self.field}_{v}": forms.CharField(
            required=False, max_length=300, label=f"Label of {v}",
            help_text="all blank: the default gait anchors" if i == 0 else "") for i, v in enumerate(self.vocabulary)}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``anchors`` when every key is a scale value and every label a non-blank, unpadded string."""
        anchors = data.get(self.key)
        if not isinstance(anchors, dict) or not anchors or not all(
                k in self.vocabulary and isinstance(v, str) and v.strip() == v and v for k, v in anchors.items()):
            return {}, data
        return ({f"{self.field}_{k}": v for k, v in anchors.items()},
                {k: v for k, v in data.items() if k != self.key})

    def write(self, values: dict) -> dict:
        """``anchors`` of the filled-in labels, nothing when all are blank."""
        anchors = {v: values[f"{self.field}_{v}"] for v in self.vocabulary if values.get(f"{self.field}_{v}")}
        return {self.key: anchors} if anchors else {}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """The label box of the scale value an error names (``anchors.<value>``), else the first one."""
        value = next((k.removeprefix(f"{self.key}.") for k in keys if k.startswith(f"{self.key}.")), None)
        if value in self.vocabulary:
            return f"{self.field}_{value}"
        return f"{self.field}_{self.vocabulary[0]}" if self.key in keys or value is not None else None


class ValueSpec(ChoiceSpec):
    """One option of a plain type: text (``question``) or an integer count (``n_options``)."""

    def __init__(self, field: str, key: str, label: str, help_text: str, field_class, **field_kwargs):
        super().__init__(field, key, (), label, help_text)
        self.field_class, self.field_kwargs = field_class, field_kwargs

    def form_fields(self) -> dict[str, forms.Field]:
        """One field of the spec's field class and arguments, not required."""
        return {self.field: self.field_class(required=False, label=self.label, help_text=self.help,
                                             **self.field_kwargs)}

    def _accepts(self, value) -> bool:
        if self.field_class is forms.IntegerField:
            return _is_int(value) and self.field_kwargs.get("min_value", value) <= value <= self.field_kwargs.get(
                "max_value", value)
        return isinstance(value, str) and value.strip() == value and value != ""

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``key`` when the field could show it: an integer within the field's bounds, or a non-blank unpadded
        string."""
        if self.key in data and self._accepts(data[self.key]):
            return {self.field: data[self.key]}, {k: v for k, v in data.items() if k != self.key}
        return {}, data

    def write(self, values: dict) -> dict:
        """``key: value``, nothing when blank."""
        value = values.get(self.field)
        return {} if value is None or value == "" else {self.key: value}


class AttentionSpec(ChoiceSpec):
    """``attention_checks`` (every section type, studyapp.participant.trial_extras): ``{"answer": "sad", "count": 1,
    "positions": "random" | [3, 7], "question": "perceived"}`` as four fields; blank answer and count: none."""

    PARTS = {"answer": "instructed answer", "count": "how many", "positions": "positions", "question": "question",
             "clip": "check clip"}

    def __init__(self, field: str):
        super().__init__(field, "attention_checks", (), "Attention checks")

    def form_fields(self) -> dict[str, forms.Field]:
        """The instructed answer, count (1 to 100), positions, question and check clip fields."""
        f = self.field
        return {
            f"{f}_answer": forms.CharField(required=False, max_length=40, label="Attention check: instructed answer",
                                           help_text="the answer the participant is told to give (e.g. sad, or 3 on "
                                                     "a scale); blank: no attention checks"),
            f"{f}_count": forms.IntegerField(required=False, min_value=1, max_value=100, label="Attention checks",
                                             help_text="how many; blank: 1, or one per position"),
            f"{f}_positions": forms.CharField(required=False, max_length=200, label="Attention check positions",
                                              help_text="random, or places in the section such as 3, 7"),
            f"{f}_question": forms.CharField(required=False, max_length=40, label="Attention check question",
                                             help_text="a question key of the section; blank: its first question"),
            f"{f}_clip": forms.CharField(required=False, max_length=200, label="Attention check clip",
                                         help_text="clip_id of a clip kept for checks, one no participant rates; "
                                                   "blank: a spare clip of the pool, else the practice clip")}

    @staticmethod
    def _places(text: str) -> list[int] | None:
        parts = [p.strip() for p in text.split(",")]
        return [int(p) for p in parts] if all(p.isdigit() and int(p) >= 1 for p in parts) else None

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``attention_checks`` when every part is known and well-formed; a list of positions shows as "3, 7"."""
        config = data.get(self.key)
        if not isinstance(config, dict) or not config or set(config) - set(self.PARTS):
            return {}, data
        positions = config.get("positions", "random")
        ok = (all(isinstance(config.get(k, "x"), str) and config.get(k, "x").strip()
                  for k in ("answer", "question", "clip"))
              and (_is_int(config.get("count", 1)) and 1 <= config.get("count", 1) <= 100)
              and (positions == "random" or isinstance(positions, list) and positions
                   and all(_is_int(p) and p >= 1 for p in positions)))
        if not ok:
            return {}, data
        values = {f"{self.field}_{k}": v for k, v in config.items() if k != "positions"}
        if "positions" in config:
            values[f"{self.field}_positions"] = positions if positions == "random" else ", ".join(map(str, positions))
        return values, {k: v for k, v in data.items() if k != self.key}

    def write(self, values: dict) -> dict:
        """``attention_checks`` of the filled-in parts, positions as "random" or a list of places; nothing when all are
        blank."""
        config = {k: values.get(f"{self.field}_{k}") for k in self.PARTS}
        positions = (config["positions"] or "").strip()
        config["positions"] = "random" if positions == "random" else (self._places(positions) if positions else None)
        config = {k: v for k, v in config.items() if v not in (None, "")}
        return {self.key: config} if config else {}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """The part's field an error about ``attention_checks.<part>`` names, the answer field for the whole config."""
        parts = [k.removeprefix(f"{self.key}.") for k in keys if k == self.key or k.startswith(f"{self.key}.")]
        if not parts:
            return None
        return f"{self.field}_{next((p for p in parts if p in self.PARTS), 'answer')}"

    def check(self, values: dict) -> dict[str, str]:
        """An error on the positions field unless it says random or lists whole numbers from 1."""
        positions = (values.get(f"{self.field}_positions") or "").strip()
        if positions and positions != "random" and self._places(positions) is None:
            return {f"{self.field}_positions": "write random, or whole numbers from 1 separated by commas"}
        return {}


class NormingSpec(ChoiceSpec):
    """``norming`` (protocol.norming): ``{"ratings_per_clip": K}`` as a check box and K; ticked with K blank is
    ``{}`` (the default K). A K alone ticks the box."""

    def __init__(self, field: str):
        super().__init__(field, NORMING_OPTION, (), "Norming section")
        self.k = f"{field}_ratings_per_clip"

    def form_fields(self) -> dict[str, forms.Field]:
        """The "Norming section" check box and the ratings per clip (K, 1 to MAX_RATINGS_PER_CLIP)."""
        return {
            self.field: forms.BooleanField(
                required=False, label="Norming section",
                help_text="every clip of the pool is rated by K participants, each rating M (the clips per "
                          "participant), in a balanced design; intensity and naturalness are asked after the "
                          "section's own questions (protocol.norming)"),
            self.k: forms.IntegerField(
                required=False, min_value=1, max_value=MAX_RATINGS_PER_CLIP, label="Ratings per clip (K)",
                help_text=f"blank: {DEFAULT_RATINGS_PER_CLIP}; the study's participant limit must give every clip "
                          "K ratings before it opens")}

    def read(self, data: dict) -> tuple[dict, dict]:
        """Takes ``norming`` when it is an object holding at most a valid ``ratings_per_clip``: the box ticked, K filled
        in."""
        config = data.get(self.key)
        if not isinstance(config, dict) or set(config) - {"ratings_per_clip"}:
            return {}, data
        k = config.get("ratings_per_clip")
        if k is not None and not (_is_int(k) and 1 <= k <= MAX_RATINGS_PER_CLIP):
            return {}, data
        values = {self.field: True, **({self.k: k} if k is not None else {})}
        return values, {key: v for key, v in data.items() if key != self.key}

    def write(self, values: dict) -> dict:
        """``norming: {}`` when ticked without K, ``{"ratings_per_clip": K}`` when K is given, nothing otherwise."""
        k = values.get(self.k)
        if not values.get(self.field) and k is None:
            return {}
        return {self.key: {} if k is None else {"ratings_per_clip": k}}

    def owner(self, keys: tuple[str, ...]) -> str | None:
        """K for an error about ``norming.ratings_per_clip``, the check box for the rest of ``norming``."""
        if f"{self.key}.ratings_per_clip" in keys:
            return self.k
        return self.field if self.key in keys or any(k.startswith(f"{self.key}.") for k in keys) else None


def read_specs(specs: list[ChoiceSpec], data: dict) -> tuple[dict, dict]:
    """(field values, leftover) of ``data`` under ``specs``, each taking the keys it can show."""
    values, rest = {}, dict(data)
    for spec in specs:
        got, rest = spec.read(rest)
        values.update(got)
    return values, rest


def write_specs(specs: list[ChoiceSpec], values: dict) -> dict:
    """The JSON every spec writes from the field values, merged in the specs' order."""
    out = {}
    for spec in specs:
        out.update(spec.write(values))
    return out


# ---- the editor's groups ------------------------------------------------------------------------------------------

SUB_POOL_SECTION_TYPE = next(t.name for t in registered() if t.sub_pools)
"""The section type whose pool may hold ``generated`` / ``source`` sub-pools (its declaration's ``sub_pools``)."""


def takes_sub_pools(section_type: str | None) -> bool:
    """Whether a section type's pool may hold the ``generated`` / ``source`` sub-pools (protocol.section_types)."""
    spec = find_section_type(section_type)
    return bool(spec and spec.sub_pools)


def _main_pool_specs() -> list[ChoiceSpec]:
    p = POOL_PREFIX
    return [
        ChoiceSpec(p + "modality", "modality", CLIP_MODALITIES, "Modality"),
        ChoiceSpec(p + "origin", "origin", ORIGINS, "Origin", "none ticked: any (naturalness mixes both halves)"),
        TextListSpec(p + "plan", "plan", "Plan", "the catalogue's plan name; several separated by commas; "
                                                  "blank: any plan"),
        ChoiceSpec(p + "emotion_label", "emotion_label", GESTURE_EMOTIONS, "Emotion",
                   "the gesture clips' emotion category; none ticked: any"),
        ChoiceSpec(p + "theme", "theme", CLIP_THEMES, "Theme"),
        SignSpec(p + "weight_sign", "weight", (), "Weight sign", "the RBF style weight compared with 0"),
        RangeSpec(p + "weight", "weight", "Weight", "inclusive; blank: no limit", integer=False, exact=False),
        RangeSpec(p + "n_features", "n_features", "Feature count", "RBF features used; inclusive; blank: no limit",
                  integer=True, exact=True),
        TristateSpec(p + "transition", "transition", (), "Transition",
                     "yes: clips whose emotion changes (they have a final emotion)"),
        TristateSpec(p + "rbf", "rbf", (), "Styled", "yes: clips with a theme (RBF styled, or the neutral input walk)"),
        FlagSpec(p + "include_flagged", INCLUDE_FLAGGED, (), "Include clips that failed a quality check",
                 "on: every clip, whatever its quality flag (Clip.qa_flag); off: every flagged clip is left out "
                 "unless one of the two boxes below keeps its kind of flag"),
        FlagSpec(p + "keep_advisory", KEEP_ADVISORY, (), "Keep clips flagged only by advisory checks",
                 f"advisory checks ({', '.join(QA_ADVISORY_CHECKS)}): the realism check compares a walk's foot "
                 "skate, knee, pelvis bounce and speed with real captured walks and flags about 10 % of real takes "
                 "too; on: a clip that failed only these stays in; off: it is left out"),
        FlagSpec(p + "observer_advisory", OBSERVER_ADVISORY, (), "Observer flag is advisory",
                 "on: a clip the automatic emotion observer flagged stays in (people judge it, as in a norming "
                 "study); other failed checks still keep a clip out. A norms rule keeps the observer flag of "
                 "clips people have rated"),
    ]


def _sub_pool_specs() -> list[SubPoolSpec]:
    def inner(name: str) -> list[ChoiceSpec]:
        p, title = f"{POOL_PREFIX}{name}_", f"{name.capitalize()} clips"
        return [TextListSpec(p + "plan", "plan", f"{title}: plan", "blank: any plan"),
                ChoiceSpec(p + "emotion_label", "emotion_label", GESTURE_EMOTIONS, f"{title}: emotion"),
                TristateSpec(p + "transition", "transition", (), f"{title}: transition")]
    return [SubPoolSpec(name, inner(name)) for name in SUB_POOLS]


def _option_key_specs() -> dict[str, ChoiceSpec]:
    """Option key -> its spec: the form fields of every option a section type declares (protocol.section_types'
    ``options``). A declared key missing here is edited in the raw JSON only (tests/studyapp/admin/test_option_fields.py
    fails)."""
    o, n = OPTIONS_PREFIX, len(GESTURE_EMOTIONS)
    return {
        "anchors": AnchorsSpec(o + "anchor"),
        "question": ValueSpec(o + "question", "question", "Question", "blank: the default question", forms.CharField,
                              max_length=500),
        "n_generated": ValueSpec(o + "n_generated", "n_generated", "Generated clips per participant",
                                 "with the next: how each participant's clips split; their sum is the clips per "
                                 "participant", forms.IntegerField, min_value=0, max_value=N_FEATURES_MAX),
        "n_source": ValueSpec(o + "n_source", "n_source", "Source clips per participant",
                              "the captured clips each participant sees; blank: half the clips per participant",
                              forms.IntegerField, min_value=0, max_value=N_FEATURES_MAX),
        "n_options": ValueSpec(o + "n_options", "n_options", "Answer options shown",
                               f"2 to {n}, the intended emotion among them; blank: {DEFAULT_GESTURE_OPTIONS}",
                               forms.IntegerField, min_value=2, max_value=n),
        "categories": ChoiceSpec(o + "categories", "categories", GESTURE_EMOTIONS, "Emotions offered",
                                 f"none ticked: all {n}"),
        NORMING_OPTION: NormingSpec(o + NORMING_OPTION),
        WAIT_OPTION: ValueSpec(o + WAIT_OPTION, WAIT_OPTION, "Wait before Continue (seconds)",
                               f"Continue is enabled this long after the page is first shown (the server checks it "
                               f"too); blank: {DEFAULT_WAIT_SECONDS}", forms.IntegerField, min_value=0,
                               max_value=MAX_WAIT_SECONDS),
    }


OPTION_KEY_SPECS = _option_key_specs()


def _option_specs() -> dict[str, list[ChoiceSpec]]:
    """Section type -> the specs of the options its declaration takes, in declaration order (the types registered
    when this module is imported)."""
    return {t.name: [OPTION_KEY_SPECS[key] for key in t.option_keys if key in OPTION_KEY_SPECS]
            for t in registered(pages=True) if t.options}


def _common_option_specs() -> list[ChoiceSpec]:
    """Options every section type takes (protocol.pools.COMMON_OPTIONS)."""
    o = OPTIONS_PREFIX
    specs = [FlagSpec(o + "practice", "practice", (), "Practice item first",
                      "one practice clip (not exported) from outside the pool, of the section's modality"),
             ValueSpec(o + "practice_clip", "practice_clip", "Practice clip", "a clip_id of the catalogue; blank: "
                       "drawn at random when the box above is ticked", forms.CharField, max_length=200),
             AttentionSpec(o + "attention"),
             SelectSpec(o + "controls", "controls", PLAYER_CONTROLS, "Player controls",
                        "replay-only: play/pause and replay, no seek bar or speed; full: the browser's controls "
                        "(seeking allowed); none: the clip plays by itself, replay once it ended",
                        DEFAULT_PLAYER_CONTROLS),
             ValueSpec(o + "max_replays", "max_replays", "Replays allowed", "plays after the first; blank: unlimited, "
                       "0: the clip plays once", forms.IntegerField, min_value=0, max_value=MAX_REPLAYS_LIMIT)]
    return [spec for spec in specs if spec.key in COMMON_OPTIONS]


MAIN_POOL_SPECS = _main_pool_specs()
SUB_POOL_SPECS = _sub_pool_specs()
COMMON_OPTION_SPECS = _common_option_specs()
OPTION_SPECS = _option_specs()
TYPE_OPTION_SPECS = list({id(spec): spec for group in OPTION_SPECS.values() for spec in group}.values())
"""Every section type's own option specs, each once (``norming`` is taken by several types)."""
ALL_OPTION_SPECS = [*COMMON_OPTION_SPECS, *TYPE_OPTION_SPECS]


def _names(specs) -> list[str]:
    return [name for spec in specs for name in spec.form_fields()]


MAIN_POOL_FIELDS = _names(MAIN_POOL_SPECS)
SUB_POOL_FIELDS = _names(SUB_POOL_SPECS)
POOL_FIELDS = MAIN_POOL_FIELDS + SUB_POOL_FIELDS
OPTION_FIELDS = {stype: _names(specs) for stype, specs in OPTION_SPECS.items()}
"""section type -> the fields of its own options (COMMON_OPTION_FIELDS: every type's)."""


def _option_groups() -> list[tuple[tuple[str, ...], list[str]]]:
    """The option fieldsets of the section form: (the section types that take them, their fields); an option
    several types take (``norming``) is one group for all of them, so each field is on the page once."""
    groups: dict[tuple[str, ...], list[str]] = {}
    for spec in TYPE_OPTION_SPECS:
        types = tuple(stype for stype, specs in OPTION_SPECS.items() if spec in specs)
        groups.setdefault(types, []).extend(spec.form_fields())
    return list(groups.items())


OPTION_GROUPS = _option_groups()
COMMON_OPTION_FIELDS = _names(COMMON_OPTION_SPECS)
ALL_OPTION_FIELDS = _names(ALL_OPTION_SPECS)


def form_fields() -> dict[str, forms.Field]:
    """Every structured field of the editor, by form field name (fresh instances)."""
    specs = [*MAIN_POOL_SPECS, *SUB_POOL_SPECS, *ALL_OPTION_SPECS]
    return {name: field for spec in specs for name, field in spec.form_fields().items()}


PoolEditorFields = type("PoolEditorFields", (forms.Form,), {
    "__module__": __name__, "__doc__": "The pool editor's structured fields, for a form to inherit.", **form_fields()})


def _option_specs_of(section_type: str | None) -> list[ChoiceSpec]:
    return COMMON_OPTION_SPECS + OPTION_SPECS.get(section_type or "", []) if section_type else []


def _pool_specs(section_type: str | None) -> list[ChoiceSpec]:
    return MAIN_POOL_SPECS + (SUB_POOL_SPECS if takes_sub_pools(section_type) else [])


def pool_to_fields(pool) -> tuple[dict, dict]:
    """(field values, leftover keys) of a pool; a pool that is not a JSON object shows as no values, no leftover."""
    return read_specs(MAIN_POOL_SPECS + SUB_POOL_SPECS, pool) if isinstance(pool, dict) else ({}, {})


def fields_to_pool(values: dict, leftover: dict | None = None, section_type: str | None = None) -> dict:
    """The pool the field values mean, on top of the leftover keys (sub-pools merged key by key). Sub-pool fields
    count only for the section type that has sub-pools."""
    pool = dict(leftover or {})
    for key, value in write_specs(_pool_specs(section_type), values).items():
        if key in SUB_POOLS and isinstance(pool.get(key), dict):
            pool[key] = {**pool[key], **value}
        else:
            pool[key] = value
    return pool


def options_to_fields(options) -> tuple[dict, dict]:
    """(field values, leftover keys) of a section's options (every section type's fields are read)."""
    return read_specs(ALL_OPTION_SPECS, options) if isinstance(options, dict) else ({}, {})


def fields_to_options(values: dict, leftover: dict | None = None, section_type: str | None = None) -> dict:
    """The options the field values of ``section_type`` mean, on top of the leftover keys."""
    return {**(leftover or {}), **write_specs(_option_specs_of(section_type), values)}


def initial_values(pool, options) -> dict:
    """Initial values of every structured field for a saved pool and options."""
    return {**pool_to_fields(pool)[0], **options_to_fields(options)[0]}


GROUPS = {"pool": (POOL_FIELDS, pool_to_fields, fields_to_pool, _pool_specs),
          "options": (ALL_OPTION_FIELDS, options_to_fields, fields_to_options, _option_specs_of)}
"""raw JSON field -> (its structured fields, reader, writer, the specs a section type writes)."""


def touched_groups(changed: list[str] | set[str]) -> dict[str, bool]:
    """Raw JSON field -> whether one of its structured fields is among the changed field names."""
    changed = set(changed)
    return {group: bool(changed & set(fields)) for group, (fields, *_rest) in GROUPS.items()}


def _owner(specs: list[ChoiceSpec], keys: tuple[str, ...], values: dict) -> str | None:
    """The structured field an error about these JSON keys (protocol.pools.SectionError.keys) belongs to: the spec
    that wrote the key (a key that came from the raw JSON's leftover is the raw field's)."""
    for spec in specs:
        if isinstance(spec, SubPoolSpec):
            prefix = f"{spec.key}."
            inner = tuple(k.removeprefix(prefix) for k in keys if k.startswith(prefix))
            parts = spec.inner
        else:
            inner, parts = tuple(k for k in keys if "." not in k or k.split(".")[0] not in SUB_POOLS), [spec]
        tops = {k.split(".")[0] for k in inner}
        for part in parts:
            if tops & set(part.write(values)) and (field := part.owner(inner)):
                return field
    return None


def _build_group(form, cleaned: dict, group: str, section_type: str) -> None:
    """Replace cleaned[group] by the JSON the structured fields mean (plus the raw JSON's leftover keys)."""
    fields, reader, writer, specs_of = GROUPS[group]
    specs = specs_of(section_type)
    names = _names(specs)
    values = {name: cleaned.get(name) for name in names}
    for spec in specs:
        if not any(form.has_error(name) for name in spec.form_fields()):
            for name, message in spec.check(values).items():
                form.add_error(name, message)
    if any(form.has_error(name) for name in names):
        cleaned.pop(group, None)         # each field's error says what to fix; the JSON cannot be built
        return
    cleaned[group] = writer(values, reader(cleaned.get(group) or {})[1], section_type)


def resolve_section_json(form, cleaned: dict, touched: dict[str, bool]) -> None:
    """Settle a section form's ``pool`` and ``options`` in ``cleaned`` and report every problem on a field.

    touched: raw JSON field -> whether its structured fields were edited (then they win, see the module's doc).
    An error of the built JSON goes to the structured field owning its key, else to the raw JSON field; a group
    with an error leaves ``cleaned`` so the model's clean does not report it again.
    """
    section_type = cleaned.get("section_type")
    for group in GROUPS:
        if cleaned.get(group) is None and not form.has_error(group):
            cleaned[group] = {}          # a blank box is an empty pool / no options
    if form.has_error("section_type") or not section_type:
        return
    for group in GROUPS:
        if touched.get(group) and not form.has_error(group):
            _build_group(form, cleaned, group, section_type)
    errors = validate_section(section_type, cleaned.get("pool"), cleaned.get("options"),
                              cleaned.get("clips_per_participant"))
    for name in dict.fromkeys(error.field for error in errors):
        if name not in form.fields or form.has_error(name):
            continue
        specs = GROUPS[name][3](section_type) if touched.get(name) and name in GROUPS else []
        values = {field: cleaned.get(field) for field in _names(specs)}
        for error in errors:
            if error.field == name:
                form.add_error(_owner(specs, error.keys, values) or name, error.message)
        cleaned.pop(name, None)
