"""Every report figure keeps its text inside the canvas at the size it ships: titles, tick labels, axis labels,
legends and colour-bar labels, measured with matplotlib's tight bounding boxes after a draw."""
from __future__ import annotations

import pytest

from analysis import figures
from analysis.io import load_study
from analysis.report import build_report, make_figures
from analysis.simulate import write_study

TOLERANCE_PX = 1.0
SMALL = ("fig_emotion_vectors", "fig_transitions", "fig_likert", "fig_theme_ratings")
NAMES = ["fig_emotion_vectors", "fig_transitions", "fig_likert", "fig_vad", "fig_naturalness", "fig_theme_ratings",
         "fig_inversion", "fig_confusion", "fig_clip_norms_gait", "fig_clip_norms_gesture"]


def text_outside(fig) -> list[str]:
    """What of ``fig`` is drawn outside its canvas: matplotlib's tight bounding box of the whole figure (every drawn
    title, tick label, axis label, legend, colour bar), then per axes and for the suptitle to name the culprit."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    width, height = fig.get_size_inches()
    tol = TOLERANCE_PX / fig.dpi

    def outside(box) -> bool:
        return box.x0 < -tol or box.y0 < -tol or box.x1 > width + tol or box.y1 > height + tol

    if not outside(fig.get_tightbbox(renderer)):
        return []
    inches = fig.dpi_scale_trans.inverted()
    parts = [(f"axes {ax.get_title()!r}", ax.get_tightbbox(renderer)) for ax in fig.axes if ax.get_visible()]
    title = getattr(fig, "_suptitle", None)
    if title is not None:
        parts.append((f"suptitle {title.get_text()!r}", title.get_window_extent(renderer)))
    parts = [(name, box.transformed(inches)) for name, box in parts if box is not None]
    named = [f"{name}: x {b.x0:.2f}..{b.x1:.2f} of {width:.2f} in, y {b.y0:.2f}..{b.y1:.2f} of {height:.2f} in"
             for name, b in parts if outside(b)]
    return named or ["the figure's tight bounding box leaves the canvas"]


def _small(tables: dict) -> dict:
    """The tables cut to one clip, one emotion or one theme: the narrow figures a small study gets."""
    out = dict(tables)
    for key in ("gait_emotion_ad", "transition_ad"):
        if not tables[key].empty:
            out[key] = tables[key][tables[key]["clip_id"] == tables[key]["clip_id"].iloc[0]]
    if not tables["likert_distribution"].empty:
        d = tables["likert_distribution"]
        out["likert_distribution"] = d[d["emotion"] == d["emotion"].iloc[0]]
    if not tables["theme_descriptives"].empty:
        d = tables["theme_descriptives"]
        out["theme_descriptives"] = d[d["theme"] == d["theme"].iloc[0]]
    return out


@pytest.fixture(scope="module")
def every_figure(tmp_path_factory):
    src = tmp_path_factory.mktemp("study")
    paths = write_study(str(src), 24, seed=9)
    data = load_study(paths["responses"], paths["clips"], paths["participants"])
    _, tables, extras = build_report(data)
    return {**make_figures(tables, extras),
            **{f"{name} (small study)": fig for name, fig in make_figures(_small(tables), extras).items()
               if name in SMALL}}


def test_every_report_figure_is_drawn(every_figure):
    drawn = {name for name, fig in every_figure.items() if fig is not None}
    assert {"fig_transitions", "fig_likert", "fig_emotion_vectors", "fig_vad", "fig_naturalness",
            "fig_theme_ratings", "fig_inversion", "fig_confusion"} <= drawn


@pytest.mark.parametrize("name", [*NAMES, *(f"{n} (small study)" for n in SMALL)])
def test_no_text_outside_the_canvas(every_figure, name):
    fig = every_figure.get(name)
    if fig is None:
        pytest.skip(f"{name}: the simulated study has no data for it")
    assert text_outside(fig) == []
    figures.plt.close(fig)
