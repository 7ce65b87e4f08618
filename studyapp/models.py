"""Database models of the study platform.

Study -> Section (ordered, typed, configured) -> per-participant Assignment (ordered clips, fixed at start)
-> Response (one row per participant, section, clip and question; unique in the database).
Clip rows mirror the public `clips.csv` columns of DESIGN.md plus media paths.
"""
from __future__ import annotations

import secrets

from django.conf import settings
from django.core.exceptions import ValidationError
from django.core.validators import MaxValueValidator
from django.db import models
from django.utils import timezone

from protocol.dictionary import PILOT_PREFIX
from protocol.pools import errors_by_field, validate_section
from protocol.section_types import is_page_type
from protocol.titles import TITLE_MAX_LENGTH
from protocol.vocabulary import ATTENTION_CHECK, BODY_MAX_LENGTH, CLIP_MODALITIES, ORIGINS

from .permissions import STUDY_PERMISSIONS
from .questions import section_type_choices
from .redirects import check_completion_url, safe_completion_url

DEFAULT_ABANDON_MINUTES = 120
"""A new study's ``abandon_after_minutes``: two hours, longer than any preset's expected duration several times over."""

MAX_STUDY_VIEWPORT_PX = 4000
"""The largest minimum viewport side (CSS pixels) a study may ask for."""


def new_token() -> str:
    """An unguessable participant credential (URL-safe, 32 random bytes)."""
    return secrets.token_urlsafe(32)


def new_public_id() -> str:
    """The participant id written to exports: opaque, not a credential."""
    return "p" + secrets.token_hex(6)


def new_media_key() -> str:
    """The default Clip.media_key: 32 random hex digits that name the clip's media URL without revealing its id."""
    return secrets.token_hex(16)


def new_seed() -> int:
    """The default Participant.seed: a random integer in [0, 2**31 - 1) that fixes the participant's clip plan."""
    return secrets.randbelow(2**31 - 1)


def new_completion_code() -> str:
    """The default Study.completion_code: 8 random upper-case hex digits, filled into the completion URL's {code}."""
    return secrets.token_hex(4).upper()


class Clip(models.Model):
    """One pre-rendered stimulus; fields follow the `clips.csv` columns of DESIGN.md."""

    clip_id = models.CharField(max_length=200, unique=True)
    # A readable label for staff pages and exports (protocol.titles: generator, condition, variant); never shown
    # to participants.
    title = models.CharField(max_length=TITLE_MAX_LENGTH, blank=True)
    body = models.CharField(max_length=BODY_MAX_LENGTH, blank=True,
                            help_text="The human body preset the clip shows (blank: a mannequin, stick figure or "
                                      "point-lights, or an imported video)")
    modality = models.CharField(max_length=10, choices=[(m, m) for m in CLIP_MODALITIES])
    origin = models.CharField(max_length=10, choices=[(o, o) for o in ORIGINS])
    happy = models.FloatField(null=True, blank=True)
    sad = models.FloatField(null=True, blank=True)
    angry = models.FloatField(null=True, blank=True)
    neutral = models.FloatField(null=True, blank=True)
    final_happy = models.FloatField(null=True, blank=True)
    final_sad = models.FloatField(null=True, blank=True)
    final_angry = models.FloatField(null=True, blank=True)
    final_neutral = models.FloatField(null=True, blank=True)
    emotion_label = models.CharField(max_length=40, blank=True)
    valence = models.FloatField(null=True, blank=True)
    arousal = models.FloatField(null=True, blank=True)
    dominance = models.FloatField(null=True, blank=True)
    theme = models.CharField(max_length=40, blank=True)
    weight = models.FloatField(null=True, blank=True)
    n_features = models.IntegerField(null=True, blank=True)
    duration_s = models.FloatField(null=True, blank=True)
    # Generated clip -> the clip_id of the source clip it was made from (seed 003: never show both to one person).
    source_clip_id = models.CharField(max_length=200, blank=True)
    video = models.CharField(max_length=500, help_text="MP4 path relative to MEDIA_ROOT")
    webm = models.CharField(max_length=500, blank=True)
    poster = models.CharField(max_length=500, blank=True)
    plan = models.CharField(max_length=100, blank=True)
    # The plan's hint of the section types the clip is meant for, comma-separated (pool filter sections__contains).
    sections = models.CharField(max_length=300, blank=True)
    loop = models.BooleanField(default=False)
    metadata = models.JSONField(default=dict, blank=True)
    # Per-clip quality record: the qa_* values of clips.csv without the prefix, e.g.
    # {"foot_skate_cm_s": 0.4, "figure_height_frac": 0.62, "observed": "sad", "observed_p": 0.91}.
    qa = models.JSONField(default=dict, blank=True)
    # What the clip was made from may only be used under its licence and with its citation (imported files,
    # captured data): kept with the clip and written to clips.csv.
    licence = models.CharField(max_length=300, blank=True)
    citation = models.TextField(blank=True)
    qa_flag = models.CharField(max_length=300, blank=True, db_index=True,
                               help_text="failed quality checks joined by ';' (empty = passed)")
    retired = models.BooleanField(
        default=False, help_text="superseded by a newer render of the same plan entry (e.g. after a generator "
        "changed); kept for the answers that refer to it, left out of new assignments")
    media_key = models.CharField(max_length=32, unique=True, default=new_media_key, editable=False)
    created_at = models.DateTimeField(auto_now_add=True)
    updated_at = models.DateTimeField(auto_now=True)

    class Meta:
        """Clips listed by clip id."""

        ordering = ["clip_id"]

    def __str__(self) -> str:
        return self.clip_id

    @property
    def is_transition(self) -> bool:
        """True for a transition clip: one with final emotion values (``final_happy`` set)."""
        return self.final_happy is not None


class Study(models.Model):
    """A study: its participant-facing texts and settings, its sections (Section) and participants, and who may manage
    it (owners) or see it (collaborators)."""

    class Status(models.TextChoices):
        """Draft (being set up), open (taking participants) or closed."""

        DRAFT = "draft", "Draft"
        OPEN = "open", "Open"
        CLOSED = "closed", "Closed"

    slug = models.SlugField(max_length=80, unique=True)
    title = models.CharField(max_length=200)
    preset = models.CharField(max_length=40, blank=True)
    status = models.CharField(max_length=10, choices=Status.choices, default=Status.DRAFT)
    introduction = models.TextField(blank=True)
    consent_text = models.TextField(blank=True)
    ask_demographics = models.BooleanField(default=True)
    feedback_questions = models.JSONField(
        default=list, blank=True,
        help_text='List of {"key": "camera", "text": "Were you distracted ...?", "kind": "yesno"|"text"}')
    max_participants = models.PositiveIntegerField(default=0, help_text="0 = no limit")
    abandon_after_minutes = models.PositiveIntegerField(
        default=DEFAULT_ABANDON_MINUTES,
        help_text="A started participant inactive this long stops counting towards the participant limit, so the "
                  "places of people (or scripts) who left free up; they may still come back and finish (0 = never)")
    export_external_ids = models.BooleanField(
        default=False, help_text="Exports and reports carry participants' external ids (Prolific IDs) as given. Off: "
                                 "each is a pseudonym, the same for one participant in every export of this study; "
                                 "the ids for payment are a separate download (permission: download payment ids)")
    listed_publicly = models.BooleanField(
        default=False, help_text="List this study on the site's front page while it is open. Off: only people "
                                 "with its link (Prolific, e-mail) find it")
    completion_code = models.CharField(max_length=40, default=new_completion_code)
    completion_redirect = models.CharField(
        max_length=500, blank=True,
        help_text="Optional URL shown/redirected to at the end; {code} is replaced by the completion code, e.g. "
                  "https://app.prolific.com/submissions/complete?cc={code}")
    redirect_automatically = models.BooleanField(
        default=False, help_text="Send participants to the completion URL a few seconds after the last page")
    language = models.CharField(max_length=8, default="en", choices=[("en", "English"), ("de", "Deutsch")],
                                help_text="Language of every participant-facing page; exports stay in the "
                                          "protocol's labels")
    counterbalance_sections = models.BooleanField(
        default=False, help_text="Rotate the order of the sections across participants (Latin square); each "
                                 "participant's order is recorded and exported")
    min_viewport_width = models.PositiveSmallIntegerField(
        default=0, validators=[MaxValueValidator(MAX_STUDY_VIEWPORT_PX)],
        help_text="Smallest browser window width (CSS pixels) a participant may start with; checked on the consent "
                  "page (0: the player's own minimum, 320)")
    min_viewport_height = models.PositiveSmallIntegerField(
        default=0, validators=[MaxValueValidator(MAX_STUDY_VIEWPORT_PX)],
        help_text="Smallest browser window height (CSS pixels); 0: the player's own minimum, 300")
    admit_phones = models.BooleanField(default=True, help_text="Participants on a phone may take part")
    admit_tablets = models.BooleanField(default=True, help_text="Participants on a tablet may take part")
    exclusion_rules = models.JSONField(
        default=dict, blank=True,
        help_text="Rules the analysis applies (raw exports stay unchanged), e.g. "
                  '{"min_rt_fraction": 0.25, "max_straightline": 0.9, "min_attention_pass": 1.0}')
    pilot = models.BooleanField(
        default=False, help_text="Pilot mode: the study takes participants while it is still a draft, and everyone "
                                 "who consents while this is on is a pilot participant: marked in every export (their "
                                 "id starts with 'pilot-'), left out of the analysis report unless the box below is "
                                 "ticked, and removed by 'delete pilot data' on the progress page")
    report_includes_pilot = models.BooleanField(
        default=False, help_text="Include the pilot participants in the analysis report (they are always in the "
                                 "CSV exports, marked)")
    # Who may see, preview, export and analyse the study (studyapp.permissions.studies_for); superusers see every
    # study. Owners also decide who the owners and collaborators are.
    owners = models.ManyToManyField(settings.AUTH_USER_MODEL, blank=True, related_name="owned_studies",
                                    help_text="Researchers who run this study and manage who else may see it")
    collaborators = models.ManyToManyField(settings.AUTH_USER_MODEL, blank=True, related_name="shared_studies",
                                           help_text="Researchers who may see, preview, export and analyse it")
    created_at = models.DateTimeField(auto_now_add=True)

    class Meta:
        """Newest first; the study permissions of studyapp.permissions beside Django's own."""

        verbose_name_plural = "studies"
        ordering = ["-created_at"]
        permissions = STUDY_PERMISSIONS

    def __str__(self) -> str:
        return self.title

    def clean(self):
        """Refuse a completion redirect that is not a safe http(s) URL, as an error on that field of the study's admin
        page."""
        try:
            check_completion_url(self.completion_redirect)
        except ValidationError as exc:
            raise ValidationError({"completion_redirect": exc.messages}) from None

    def completion_url(self) -> str:
        """The completion URL with the code filled in; "" when there is none or it is not http(s)."""
        url = self.completion_redirect.replace("{code}", self.completion_code) if self.completion_redirect else ""
        return safe_completion_url(url)


class Section(models.Model):
    """A block of clips with one question set, or an instruction or break page (a page type: no clips, no
    questions; studyapp.data.section_pages); `order` fixes the position in the study."""

    study = models.ForeignKey(Study, on_delete=models.CASCADE, related_name="sections")
    order = models.PositiveIntegerField(default=0)
    section_type = models.CharField(max_length=30, choices=section_type_choices)
    name = models.CharField(max_length=200, blank=True,
                            help_text="The researchers' name for the section (admin, previews, reports); never shown "
                                      "to participants")
    title = models.CharField(max_length=200, blank=True,
                             help_text="The heading participants see on its clip pages, in their words (blank: plain "
                                       "words for the section type, e.g. \"How does this walk look?\"); of an "
                                       "instruction or break page: its title")
    instructions = models.TextField(blank=True, help_text="What participants are asked to do, shown above the clip "
                                                          "(blank: the section type's plain-words default); of an "
                                                          "instruction or break page: its text")
    pool = models.JSONField(
        default=dict, blank=True,
        help_text='Clip pool as catalogue filters, e.g. {"modality": "gait", "origin": "generated", '
                  '"transition": false, "weight__gt": 0}. For naturalness use "generated" and "source" sub-filters.')
    clips_per_participant = models.PositiveIntegerField(default=6, help_text="0 = every clip of the pool")
    reuse_section = models.ForeignKey(
        "self", null=True, blank=True, on_delete=models.SET_NULL, related_name="reused_by",
        help_text="Show the clips this participant got in that earlier section (seed 000 section 3).")
    randomize_order = models.BooleanField(default=True)
    require_full_play = models.BooleanField(default=True, help_text="Answers are enabled once the clip has played")
    loop = models.BooleanField(default=False)
    options = models.JSONField(
        default=dict, blank=True,
        help_text='Type-specific options, e.g. naturalness {"anchors": {"1": "not natural at all", ...}, '
                  '"n_generated": 3, "n_source": 3}; gesture_emotion {"n_options": 4}; any section '
                  '{"attention_checks": {"count": 1, "answer": "sad", "positions": "random"}, "practice": true} '
                  'or {"practice_clip": "<clip_id>"}')
    counterbalance = models.BooleanField(
        default=True, help_text="Rotates with the other rotating sections when the study counterbalances its "
                                "section order; untick to pin this section to its place (e.g. a final section). "
                                "An instruction or break page travels with the section that follows it (its own "
                                "tick is not used); a page after the last section stays last")

    class Meta:
        """A study's sections in their order."""

        ordering = ["study", "order", "id"]

    def __str__(self) -> str:
        return f"{self.study.slug} #{self.order} {self.section_type}" + (f" ({self.name})" if self.name else "")

    def protocol_errors(self) -> dict[str, list[str]]:
        """Field -> messages for a bad pool, options or count (protocol.pools; no database query)."""
        return errors_by_field(validate_section(self.section_type, self.pool, self.options,
                                                self.clips_per_participant))

    def clean(self):
        """Check the section on its admin form: the pool, options and clip count (protocol_errors), that a reused
        section is an earlier clip section of the same study (no page type on either side), and that a named practice
        clip exists. Raises ValidationError keyed by field."""
        errors: dict[str, list[str]] = dict(self.protocol_errors())
        if self.reuse_section_id:
            other = self.reuse_section
            if is_page_type(self.section_type) or is_page_type(other.section_type):
                errors["reuse_section"] = ["An instruction or break page has no clips: it can neither reuse "
                                           "another section's clips nor be reused."]
            elif other.study_id != self.study_id:
                errors["reuse_section"] = ["The reused section must belong to the same study."]
            elif (other.order, other.pk or 0) >= (self.order, self.pk or 10**12):
                errors["reuse_section"] = ["The reused section must come before this one."]
        practice_clip = (self.options or {}).get("practice_clip") if isinstance(self.options, dict) else None
        if isinstance(practice_clip, str) and practice_clip and not Clip.objects.filter(clip_id=practice_clip).exists():
            errors.setdefault("options", []).append(f"'practice_clip': no clip {practice_clip!r} in the catalogue")
        if errors:
            raise ValidationError(errors)


class Participant(models.Model):
    """One person taking a study, from consent on: the unguessable token of their URL, the public id of the exports, the
    external (Prolific) id, the seed of their clip plan, their status and their instruction and break pages."""

    class Status(models.TextChoices):
        """Where the participant stands: consented, started (clips assigned), completed or withdrawn."""

        CONSENTED = "consented", "Consented"
        STARTED = "started", "Started"
        COMPLETED = "completed", "Completed"
        WITHDRAWN = "withdrawn", "Withdrawn"

    study = models.ForeignKey(Study, on_delete=models.CASCADE, related_name="participants")
    token = models.CharField(max_length=64, unique=True, default=new_token, editable=False)
    public_id = models.CharField(max_length=20, unique=True, default=new_public_id, editable=False)
    external_id = models.CharField(max_length=100, blank=True, help_text="e.g. Prolific PROLIFIC_PID")
    external_study_id = models.CharField(max_length=100, blank=True)
    external_session_id = models.CharField(max_length=100, blank=True)
    gender = models.CharField(max_length=30, blank=True)
    age_group = models.CharField(max_length=20, blank=True)
    demographics_done = models.BooleanField(default=False)
    feedback = models.JSONField(default=dict, blank=True)
    feedback_done = models.BooleanField(default=False)
    status = models.CharField(max_length=10, choices=Status.choices, default=Status.CONSENTED)
    seed = models.BigIntegerField(default=new_seed)
    consented_at = models.DateTimeField(default=timezone.now)
    started_at = models.DateTimeField(null=True, blank=True)
    last_active_at = models.DateTimeField(null=True, blank=True)
    completed_at = models.DateTimeField(null=True, blank=True)
    user_agent = models.CharField(max_length=300, blank=True)
    # The browser window and kind of device at consent (studyapp.participant.device_check): CSS pixels, null when not
    # reported.
    viewport_width = models.PositiveSmallIntegerField(null=True, blank=True, editable=False)
    viewport_height = models.PositiveSmallIntegerField(null=True, blank=True, editable=False)
    device_kind = models.CharField(max_length=10, blank=True, default="", editable=False,
                                   choices=[("phone", "Phone"), ("tablet", "Tablet"), ("desktop", "Desktop")])
    # Section pks in the order this participant takes them (counterbalanced studies); empty = the study's order.
    section_order = models.JSONField(default=list, blank=True)
    # SHA-256 of the one-time key the consent page gave this browser session: a second submit of the same
    # consent form (double click, two requests in flight) finds this participant instead of creating another.
    consent_key = models.CharField(max_length=64, blank=True, default="", editable=False)
    # Number of clip pages (assignments) fixed at start: the "of N" of the progress, without counting rows.
    n_items = models.PositiveIntegerField(default=0, editable=False)
    # Consented while the study was in pilot mode (Study.pilot): public_id starts with PILOT_PREFIX.
    pilot = models.BooleanField(default=False, editable=False, db_index=True)
    # The instruction and break pages this participant is given, fixed at start in the order taken
    # (studyapp.data.section_pages): section pk, the clip number they come before, when first shown and when continued.
    pages = models.JSONField(default=list, blank=True, editable=False)

    class Meta:
        """One participant per external id and per consent key in a study (blank ones exempt)."""

        constraints = [
            models.UniqueConstraint(fields=["study", "external_id"], condition=~models.Q(external_id=""),
                                    name="unique_external_id_per_study"),
            models.UniqueConstraint(fields=["study", "consent_key"], condition=~models.Q(consent_key=""),
                                    name="unique_consent_key_per_study"),
        ]

    def __str__(self) -> str:
        return self.public_id

    def save(self, *args, **kwargs):
        """A participant who consents while the study is in pilot mode is a pilot participant, and says so in the
        id every export carries."""
        if self._state.adding and not self.pilot and self.study.pilot:
            self.pilot = True
        if self.pilot and not self.public_id.startswith(PILOT_PREFIX):
            self.public_id = PILOT_PREFIX + self.public_id
        super().save(*args, **kwargs)


class Assignment(models.Model):
    """Clip `position` of `section` for one participant, fixed when the participant starts; `seq` numbers the
    participant's clip pages 1..n over the whole study in the order they are shown (the URL's clip number)."""

    class Kind(models.TextChoices):
        """What an assignment is: a trial (exported), a practice item (never exported) or an attention check."""

        TRIAL = "", "Trial"
        PRACTICE = "practice", "Practice (never exported)"
        ATTENTION = ATTENTION_CHECK, "Attention check"

    participant = models.ForeignKey(Participant, on_delete=models.CASCADE, related_name="assignments")
    section = models.ForeignKey(Section, on_delete=models.CASCADE, related_name="assignments")
    position = models.PositiveIntegerField()
    clip = models.ForeignKey(Clip, on_delete=models.PROTECT, related_name="assignments")
    options = models.JSONField(default=list, blank=True, help_text="Answer options shown (gesture_emotion)")
    shown_at = models.DateTimeField(null=True, blank=True)
    answered_at = models.DateTimeField(null=True, blank=True)
    seq = models.PositiveIntegerField(default=0)
    kind = models.CharField(max_length=20, choices=Kind.choices, default=Kind.TRIAL, blank=True)
    # Attention check: the answer the participant is told to give (Section.options["attention_checks"]["answer"]).
    instructed = models.CharField(max_length=40, blank=True, default="")
    # How the clip was watched before the answer (studyapp.participant.viewing): protocol.vocabulary.VIEWING_FIELDS ->
    # int or null; null when the browser sent no record. Exported as viewing.csv.
    viewing = models.JSONField(null=True, blank=True, editable=False)
    # The clip's playback as the player reported it while the page was open
    # (studyapp.participant.viewing.record_playback), kept across reloads so a reload neither restarts the count nor
    # resets max_replays: plays started, the ms from shown_at to the clip's first end (null: not yet), how often the
    # page was displayed, and the counts of the displays left without an answer
    # (studyapp.participant.viewing.CARRIED_FIELDS -> int), added to the answer's record.
    plays = models.PositiveIntegerField(default=0, editable=False)
    play_ended_ms = models.PositiveIntegerField(null=True, blank=True, editable=False)
    shows = models.PositiveIntegerField(default=0, editable=False)
    # when this session's player first fetched the clip (studyapp.participant.views.media): the viewing record's server
    # evidence
    fetched_at = models.DateTimeField(null=True, blank=True, editable=False)
    carried = models.JSONField(default=dict, blank=True, editable=False)

    class Meta:
        """A participant's pages by seq; one assignment per slot, per trial clip of a section and per seq, and an index
        for the first unanswered page."""

        ordering = ["participant", "seq"]
        constraints = [
            models.UniqueConstraint(fields=["participant", "section", "position"], name="unique_assignment_slot"),
            models.UniqueConstraint(fields=["participant", "section", "clip"], condition=models.Q(kind=""),
                                    name="unique_assignment_trial_clip"),
            models.UniqueConstraint(fields=["participant", "seq"], name="unique_assignment_seq"),
        ]
        indexes = [
            # The participant's current page: the first unanswered assignment by seq (one index probe).
            models.Index(fields=["participant", "seq"], condition=models.Q(answered_at__isnull=True),
                         name="assignment_unanswered"),
        ]


class Response(models.Model):
    """One answer of a participant to one question about one clip of a section, with the time it took (ms); a row of
    responses.csv."""

    participant = models.ForeignKey(Participant, on_delete=models.CASCADE, related_name="responses")
    section = models.ForeignKey(Section, on_delete=models.CASCADE, related_name="responses")
    clip = models.ForeignKey(Clip, on_delete=models.PROTECT, related_name="responses")
    question = models.CharField(max_length=60)
    answer = models.CharField(max_length=200)
    response_ms = models.PositiveIntegerField(null=True, blank=True)
    # "" for an answer to the section's question, ATTENTION_CHECK for an attention check (exported as its
    # section_type, with the instructed answer in `question`).
    kind = models.CharField(max_length=20, blank=True, default="")
    created_at = models.DateTimeField(auto_now_add=True)

    class Meta:
        """Answers in the order given; one per participant, section, clip and question."""

        ordering = ["id"]
        constraints = [
            models.UniqueConstraint(fields=["participant", "section", "clip", "question"],
                                    name="unique_response"),
        ]


class SectionClipCount(models.Model):
    """How many participants were given `clip` in `section` (trials only): the balancing counts, read without a
    lock when a participant's clips are planned and incremented with F() in the start's transaction."""

    section = models.ForeignKey(Section, on_delete=models.CASCADE, related_name="clip_counts")
    clip = models.ForeignKey(Clip, on_delete=models.CASCADE, related_name="section_counts")
    n = models.PositiveIntegerField(default=0)

    class Meta:
        """One count per section and clip."""

        constraints = [models.UniqueConstraint(fields=["section", "clip"], name="unique_section_clip_count")]


class StudyCounter(models.Model):
    """Per-study counter row: `arrivals` numbers the participants who started (the Latin-square row of a
    counterbalanced study); the row is also the short lock that keeps the participant limit exact."""

    study = models.OneToOneField(Study, on_delete=models.CASCADE, primary_key=True, related_name="counter")
    arrivals = models.PositiveIntegerField(default=0)
