import pytest
from studyapp import assignment
from studyapp.models import SectionClipCount
from tests.test_study_flow_concurrency import test_demo_starts_over_http_at_once_no_error_no_deadlock_retry as t


@pytest.mark.django_db(transaction=True)
def test_mut(settings, tmp_path, monkeypatch):
    def shuffled(sections, lock=False):
        out = {s.pk: {} for s in sections}
        rows = SectionClipCount.objects.filter(section__in=[s.pk for s in sections])
        if lock:
            rows = rows.select_for_update(no_key=True).order_by("?")
        for a, b, n in rows.values_list("section_id", "clip_id", "n"):
            out[a][b] = n
        return out
    monkeypatch.setattr(assignment, "read_counts", shuffled)
    monkeypatch.setattr(assignment._with_retries, "__defaults__", (300.0,))
    import django.test.client as dc
    orig = dc.Client.get
    def get(self, *a, **k):
        r = orig(self, *a, **k)
        if r.status_code == 500:
            import traceback
            print("EXC", "".join(traceback.format_exception(*r.exc_info))[:3000])
        return r
    monkeypatch.setattr(dc.Client, "get", get)
    t(settings, tmp_path, monkeypatch)
