"""The staff monitor of a norming study: per norming section, its design (C, M, K, N) and the ratings each clip has
so far, the clips still below K first (studyapp.data.norming). Scoped per study like every staff page: another lab's
study is a 404 (studyapp.permissions.study_of)."""
from __future__ import annotations

from django.shortcuts import render

from ..data.clip_display import clip_cells
from ..data.norming import design_rows, ratings_so_far
from ..permissions import staff_permission_required, study_of


@staff_permission_required("studyapp.view_study")
def norming_monitor(request, study_id: int):
    """The norming monitor page (studyapp.view_study): per norming section its design and each clip's ratings so far,
    with how many clips are still below K."""
    study = study_of(request, study_id)
    sections = []
    for row in design_rows(study):
        clips = ratings_so_far(row.section)
        below = [c for c in clips if c.rated < row.k]
        cells = clip_cells(c.clip_id for c in clips)
        sections.append({"design": row, "clips": clips, "below": len(below),
                         "rows": [{"c": c, "cell": cells.get(c.clip_id)} for c in clips],
                         "total_ratings": sum(c.rated for c in clips)})
    return render(request, "studyapp/staff/norming.html",
                  {"study": study, "sections": sections, "title": f"Norming monitor: {study.title}"})
