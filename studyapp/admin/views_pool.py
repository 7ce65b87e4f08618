"""The pool editor's live count: how many catalogue clips a section's pool matches, for the admin page (a small
fetch from static/studyapp/admin_pool.js while the researcher edits) and for the server-rendered page.

``GET <admin>/studyapp/study/pool-count/?section_type=...&pool_modality=gait&pool=...&touched_pool=on`` takes
the fields of one section form (names without the formset prefix) and answers JSON::

    {"count": 12, "by_origin": {"generated": 8, "source": 4}, "summary": "12 clips match ...",
     "warnings": [...], "errors": [{"field": "pool_weight_min", "label": "Weight from",
     "messages": ["Enter a number."]}], "pool": {...}, "options": {...}, "used": {"pool": "fields", ...},
     "norms_html": "<details class=\"norms-table\">...",
     "sample": [{"clip_id": "...", "title": "gait net, happy, path 1", "thumb_url": "/m/<key>.png"}, ...]}

``sample`` is the first SAMPLE_SIZE matching clips by title (studyapp.data.clip_display), so the researcher sees which
clips a pool means, not only how many.

``norms_html`` is the norms table of a pool with a ``norms`` rule (studyapp.admin.norms; escaped HTML, "" without
a rule). A norms rule may read only a study the user may see (studyapp.data.norms_rule.check_reader): another lab's
study, like one that does not exist, is an error on the pool with no count and no table.

Staff with the permission studyapp.view_clip only (403 JSON otherwise); bad input is an error in the answer
(status 200), never a 500.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from django.db import DatabaseError
from django.http import JsonResponse
from django.views.decorators.cache import never_cache

from protocol.pools import SUB_POOLS, pool_errors
from protocol.section_types import is_page_type
from protocol.vocabulary import ORIGINS

from ..data.catalogue import CatalogueError, pool_queryset, section_queryset
from ..data.clip_display import ClipCell, clip_cell
from ..data.norms_rule import NormsSourceError, check_reader
from ..permissions import has_staff_permission
from .forms import SectionPreviewForm
from .norms import norms_table
from .pool_editor import takes_sub_pools

SAMPLE_SIZE = 8
REUSED = "this section reuses the clips of an earlier section: its pool is not used"
HALVES = tuple(name for name in SUB_POOLS if name in ORIGINS)
"""The naturalness halves: each sub-pool is the clips of that origin (studyapp.participant.assignment)."""


@dataclass
class PoolCount:
    """Clips (not retired) a pool matches: ``total`` (None when the pool cannot be counted, ``errors`` say why)
    and, for a naturalness section, ``by_origin``: its generated and source halves with their sub-pools.
    ``page``: the section is an instruction or break page, which shows no clips."""

    total: int | None
    by_origin: dict[str, int] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)
    page: bool = False

    def summary(self) -> str:
        """The count as the section form shows it, e.g. "12 clips in the catalogue match (generated 6, source 6)", or
        why there is none."""
        if self.page:
            return "an instruction or break page shows no clips (leave the pool empty)"
        if self.total is None:
            return "the pool cannot be counted: " + "; ".join(self.errors)
        one = self.total == 1
        text = f"{self.total} clip{'' if one else 's'} in the catalogue match{'es' if one else ''}"
        if self.by_origin:
            text += " (" + ", ".join(f"{name} {n}" for name, n in self.by_origin.items()) + ")"
        return text

    def warnings(self, clips_per_participant: int | None, options: dict | None) -> list[str]:
        """Where the pool is too small for what a participant is shown (earlier sections may use some clips)."""
        if self.total is None or self.page:
            return []
        if self.total == 0:
            return ["no clip matches: this section would show nothing"]
        out = []
        if clips_per_participant and self.total < clips_per_participant:
            out.append(f"fewer than the {clips_per_participant} clips each participant sees")
        for name in self.by_origin:
            wanted = (options or {}).get(f"n_{name}")
            if isinstance(wanted, int) and self.by_origin[name] < wanted:
                out.append(f"fewer {name} clips ({self.by_origin[name]}) than the {wanted} each participant sees")
        return out


def count_pool(section_type: str | None, pool, reader=None) -> PoolCount:
    """Count the clips of a pool (studyapp.data.catalogue.pool_queryset); problems come back as errors, never raised.
    ``reader``: the user asking, whose studies alone a norms rule may read (None: the site, for a saved pool)."""
    if is_page_type(section_type):
        return PoolCount(0, page=True)
    errors = pool_errors(pool, section_type)
    if errors:
        return PoolCount(None, errors=errors)
    if reader is not None:
        try:
            check_reader(pool, reader)
        except NormsSourceError as exc:
            return PoolCount(None, errors=[str(exc)])
    try:
        base = section_queryset(section_type, pool or {})
        total = base.count()
        by_origin = {}
        if takes_sub_pools(section_type):
            for name in HALVES:
                half = base.filter(origin=name)
                if pool and pool.get(name):
                    # a sub-pool only narrows its section's pool (flagged clips are the main pool's call)
                    half = half.filter(pk__in=pool_queryset(pool[name], include_flagged=True).values("pk"))
                by_origin[name] = half.count()
    except (CatalogueError, DatabaseError, OverflowError, ValueError, TypeError) as exc:
        return PoolCount(None, errors=[f"the catalogue cannot count this pool ({type(exc).__name__}: {exc})"])
    return PoolCount(total, by_origin)


def pool_sample(section_type: str | None, pool, n: int = SAMPLE_SIZE) -> list[ClipCell]:
    """The first ``n`` clips (by title, then id) a valid pool matches; [] when it cannot be counted (or for a
    page, which shows none)."""
    if is_page_type(section_type) or pool_errors(pool, section_type):
        return []
    try:
        clips = section_queryset(section_type, pool or {}).order_by("title", "clip_id")[:n]
        return [clip_cell(c) for c in clips]
    except (CatalogueError, DatabaseError, OverflowError, ValueError, TypeError):
        return []


def _field_errors(form) -> list[dict]:
    out = []
    for name, messages in form.errors.items():
        label = str(form.fields[name].label or name.replace("_", " ")) if name in form.fields else name
        out.append({"field": name, "label": label, "messages": [str(m) for m in messages]})
    return out


def preview(form: SectionPreviewForm, reuse_section: str = "", reader=None) -> dict:
    """The answer for one bound preview form: count, summary, warnings, errors, and the JSON a save would store.
    ``reader``: the user asking (count_pool)."""
    form.is_valid()
    data = form.cleaned_data
    answer = {"count": None, "by_origin": {}, "summary": "", "warnings": [], "errors": _field_errors(form),
              "used": {group: "fields" if data.get(f"touched_{group}") else "raw" for group in ("pool", "options")}}
    for group in ("pool", "options"):
        if group in data:
            answer[group] = data[group]
    if "pool" not in data or "section_type" not in data:
        answer["summary"] = "fix the errors to see how many clips match"
        return answer
    counted = count_pool(data["section_type"], data["pool"], reader)
    if counted.total is None:
        answer["errors"].append({"field": "pool", "label": "pool", "messages": counted.errors})
    answer.update(count=counted.total, by_origin=counted.by_origin, summary=counted.summary(),
                  warnings=counted.warnings(data.get("clips_per_participant"), data.get("options")),
                  norms_html=str(norms_table(data["pool"])) if counted.total is not None else "",
                  sample=[vars(c) for c in pool_sample(data["section_type"], data["pool"])]
                  if counted.total is not None else [])
    if reuse_section:
        answer["warnings"].insert(0, REUSED)
    return answer


@never_cache
def pool_count(request):
    """GET only; staff with studyapp.view_clip only (403 JSON for anyone else, logged in or not)."""
    user = request.user
    if not (user.is_authenticated and user.is_active and user.is_staff):
        return JsonResponse({"error": "staff only: log in to the admin first"}, status=403)
    if not has_staff_permission(user, "studyapp.view_clip"):
        return JsonResponse({"error": "this count needs the permission studyapp.view_clip"}, status=403)
    if request.method != "GET":
        return JsonResponse({"error": "use GET"}, status=405)
    answer = preview(SectionPreviewForm(request.GET), request.GET.get("reuse_section", ""), reader=user)
    try:
        return JsonResponse(answer, json_dumps_params={"allow_nan": False})
    except ValueError:                 # a NaN/Infinity in the echoed JSON: answer without the echo
        answer.pop("pool", None)
        answer.pop("options", None)
        return JsonResponse(answer)
