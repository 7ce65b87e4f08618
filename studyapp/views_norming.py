"""The staff monitor of a norming study: per norming section, its design (C, M, K, N) and the ratings each clip has
so far, the clips still below K first (studyapp.norming)."""
from __future__ import annotations

from django.shortcuts import get_object_or_404, render

from .models import Study
from .norming import design_rows, ratings_so_far
from .permissions import staff_permission_required


@staff_permission_required("studyapp.view_study")
def norming_monitor(request, study_id: int):
    study = get_object_or_404(Study, pk=study_id)
    sections = []
    for row in design_rows(study):
        clips = ratings_so_far(row.section)
        below = [c for c in clips if c.rated < row.k]
        sections.append({"design": row, "clips": clips, "below": len(below),
                         "total_ratings": sum(c.rated for c in clips)})
    return render(request, "studyapp/staff/norming.html",
                  {"study": study, "sections": sections, "title": f"Norming monitor: {study.title}"})
