"""The pool editor's norms table: for a section whose pool has a ``norms`` rule, every clip the rest of the pool
matches with its quality record beside its norm (ratings, intended label and share with its 95 % interval,
entropy) and whether it is in the pool or why it is out (studyapp.data.norms_rule)."""
from __future__ import annotations

from django.utils.html import format_html, format_html_join
from django.utils.safestring import SafeString

from protocol.pools import NORMS_RULE, OBSERVER_ADVISORY, OBSERVER_CHECK, blocking_checks

from ..data.catalogue import CatalogueError, pool_queryset
from ..data.norms_rule import NormsSourceError, verdicts

MAX_ROWS = 200


def _quality(clip) -> str:
    qa = clip.qa or {}
    observed = qa.get("observed") or qa.get("qa_observed") or ""
    p = qa.get("observed_p") or qa.get("qa_observed_p")
    reading = f"observer: {observed}" + (f" (p {float(p):.2f})" if p not in (None, "") else "") if observed else ""
    flag = f"failed: {clip.qa_flag.replace(';', ', ')}" if clip.qa_flag else "passed"
    return "; ".join(x for x in (flag, reading) if x)


def _norm_text(norm: dict | None) -> str:
    if not norm:
        return "-"
    share = norm.get("intended_share")
    intended = norm.get("intended") or ""
    if intended and share == share and share is not None:
        lo, hi = norm.get("intended_ci_low"), norm.get("intended_ci_high")
        what = f"{intended} {share:.2f} [{lo:.2f}, {hi:.2f}]"
    else:
        what = f"top {norm.get('top_label')} {norm.get('top_share', float('nan')):.2f}"
    return f"n {int(norm['n_ratings'])}; {what}; entropy {norm.get('entropy_bits', float('nan')):.2f} bits"


def _flag_reason(clip, has_norm: bool, pool: dict) -> tuple[str, str]:
    """(reason the quality gate keeps the clip out or '', note on an observer flag made advisory or '')."""
    left = blocking_checks(clip.qa_flag, pool, normed=has_norm)
    if left:
        return f"failed quality check(s): {', '.join(left)}", ""
    plain = blocking_checks(clip.qa_flag, {k: v for k, v in pool.items() if k != OBSERVER_ADVISORY})
    if OBSERVER_CHECK not in plain:
        return "", ""
    if pool.get(OBSERVER_ADVISORY) is True:
        return "", "observer flag advisory in this pool"
    return "", "observer flag advisory: people rated this clip"


def norms_table(pool: dict | None) -> SafeString:
    """The HTML table (empty when the pool has no norms rule or it cannot be read: the count says why)."""
    pool = pool if isinstance(pool, dict) else {}
    if not isinstance(pool.get(NORMS_RULE), dict):
        return SafeString("")
    rest = {k: v for k, v in pool.items() if k != NORMS_RULE}
    try:
        clips = list(pool_queryset(rest, include_flagged=True).order_by("clip_id")[:MAX_ROWS])
        judged = verdicts(pool, [c.clip_id for c in clips])
    except (CatalogueError, NormsSourceError) as exc:
        return format_html('<p class="norms-error errornote">{}</p>', str(exc))
    rows = []
    for c in clips:
        v = judged[c.clip_id]
        gate, note = _flag_reason(c, v.norm is not None, pool)
        reasons = v.reasons + ([gate] if gate else [])
        status = "in" if not reasons else "out: " + "; ".join(reasons)
        rows.append((("norms-in" if not reasons else "norms-out"), c.clip_id, c.modality, c.origin, _quality(c),
                     _norm_text(v.norm), status + (f" ({note})" if note else "")))
    n_in = sum(r[0] == "norms-in" for r in rows)
    body = format_html_join("", '<tr class="{}"><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>'
                                "<td>{}</td></tr>", rows)
    return format_html(
        '<details class="norms-table" open><summary>Norms from <code>{}</code>: {} of {} clips in the pool</summary>'
        "<table><thead><tr><th>clip</th><th>modality</th><th>origin</th><th>quality record</th>"
        "<th>norms (ratings; intended share [95% CI]; entropy)</th><th>in the pool?</th></tr></thead>"
        "<tbody>{}</tbody></table></details>", pool[NORMS_RULE].get("from", ""), n_in, len(rows), body)
