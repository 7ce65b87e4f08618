import pytest
from studyapp import assignment
from studyapp.models import SectionClipCount
from tests.test_study_flow_concurrency import test_demo_starts_over_http_at_once_no_error_no_deadlock_retry as t


@pytest.mark.django_db(transaction=True)
def test_mut(settings, tmp_path, monkeypatch):
    calls = []
    real = assignment._retryable
    def shuffled(sections, lock=False):
        out = {s.pk: {} for s in sections}
        rows = SectionClipCount.objects.filter(section__in=[s.pk for s in sections])
        if lock:
            rows = rows.select_for_update(no_key=True).order_by("?")
        for a, b, n in rows.values_list("section_id", "clip_id", "n"):
            out[a][b] = n
        return out
    monkeypatch.setattr(assignment, "read_counts", shuffled)
    orig_wr = assignment._with_retries
    def wr(action, patience_s=300):
        import time
        d = time.monotonic() + patience_s
        while True:
            try:
                return action()
            except Exception as exc:
                v = real(exc) if isinstance(exc, assignment.OperationalError) else None
                calls.append((type(exc).__module__, type(exc).__name__, type(exc.__cause__).__name__, v))
                if not v:
                    raise
                time.sleep(0.01)
    monkeypatch.setattr(assignment, "_with_retries", wr)
    try:
        t(settings, tmp_path, monkeypatch)
    finally:
        from collections import Counter
        print("CALLS", Counter(calls))
