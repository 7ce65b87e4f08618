"""Contact sheet: a labelled grid of poster images in one PNG (for researchers, never participants)."""
from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from pathlib import Path

from PIL import Image, ImageDraw, ImageFont


def contact_sheet(poster_paths: Sequence[str | Path], labels: Sequence[str], out_png: str | Path,
                  columns: int | None = None, thumb_width: int = 320) -> Path:
    """Write a grid of thumbnails with a caption under each.

    Args:
        poster_paths: PNG files (any size; scaled to ``thumb_width`` keeping the aspect).
        labels: one caption per poster (e.g. plan entry id, emotion, theme and weight).
        out_png: output file.
        columns: grid width; default about sqrt(n) * 1.3.
    Returns the output path.
    """

    if len(poster_paths) != len(labels):
        raise ValueError(f"{len(poster_paths)} posters but {len(labels)} labels")
    if not poster_paths:
        raise ValueError("no posters for the contact sheet")
    images = []
    for p in poster_paths:
        try:
            im = Image.open(p).convert("RGB")
        except OSError as exc:
            raise ValueError(f"{p}: cannot read poster ({exc})") from None
        h = round(im.height * thumb_width / im.width)
        images.append(im.resize((thumb_width, h), Image.LANCZOS))
    n = len(images)
    cols = columns or max(1, min(n, math.ceil(math.sqrt(n) * 1.3)))
    rows = math.ceil(n / cols)
    th = max(im.height for im in images)
    caption_h, pad = 30, 6
    font = ImageFont.load_default()
    sheet = Image.new("RGB", (cols * (thumb_width + pad) + pad, rows * (th + caption_h + pad) + pad), "white")
    draw = ImageDraw.Draw(sheet)
    for i, (im, label) in enumerate(zip(images, labels)):
        r, c = divmod(i, cols)
        x, y = pad + c * (thumb_width + pad), pad + r * (th + caption_h + pad)
        sheet.paste(im, (x, y))
        text = str(label)
        # Two lines at most, broken at spaces; long captions are cut with an ellipsis.
        per_line = max(20, int(52 * thumb_width / 320))
        lines = textwrap.wrap(text, per_line) or [""]
        if len(lines) > 2:
            lines = [lines[0], lines[1][:per_line - 3] + "..."]
        for k, line in enumerate(lines):
            draw.text((x + 2, y + th + 2 + 13 * k), line, fill=(20, 20, 20), font=font)
    out_png = Path(out_png)
    out_png.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out_png)
    return out_png
