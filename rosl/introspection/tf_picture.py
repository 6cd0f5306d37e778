"""The TF tree as a picture (PDF, PNG or SVG) without Graphviz, as view_frames draws it.

Hand-written layout (a tidy tree: each frame centred over its children, one row per depth)
because Graphviz is a system package a pip install cannot bring; with Graphviz installed the
DOT output is rendered by ``dot`` instead. Pillow draws PNG and PDF; SVG is written as text.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING
from xml.sax.saxutils import escape

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.introspection.tf import Edge, TfBuffer

BOX_W, BOX_H, GAP_X, ROW_H, MARGIN = 180, 40, 30, 150, 40


@dataclass(slots=True)
class _Box:
    name: str
    x: float
    y: float
    edge: Edge | None


def layout(buffer: TfBuffer) -> tuple[list[_Box], int, int]:
    """Place each frame: leaves side by side, parents centred above their children."""
    boxes: list[_Box] = []
    next_x = [float(MARGIN)]

    def place(frame: str, depth: int, edge: Edge | None) -> float:
        children = buffer.children(frame)
        if children:
            xs = [place(child.child, depth + 1, child) for child in children]
            x = (xs[0] + xs[-1]) / 2
        else:
            x = next_x[0]
            next_x[0] += BOX_W + GAP_X
        boxes.append(_Box(frame, x, MARGIN + 30 + depth * ROW_H, edge))
        return x

    for root in buffer.roots():
        place(root, 0, None)
    width = int(max(next_x[0], BOX_W + 2 * MARGIN) + MARGIN)
    height = int(max((b.y for b in boxes), default=0) + BOX_H + MARGIN)
    return boxes, width, height


def _label(edge: Edge) -> list[str]:
    rate = "static" if edge.static else f"{edge.rate or 0.0:.1f} Hz"
    return [f"Broadcaster: {', '.join(edge.broadcasters) or 'unknown'}", f"Average rate: {rate}"]


def svg(buffer: TfBuffer, title: str) -> str:
    """The tree as an SVG document."""
    boxes, width, height = layout(buffer)
    where = {b.name: b for b in boxes}
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<text x="{MARGIN}" y="{MARGIN}" font-family="sans-serif" font-size="14">'
        f"{escape(title)}</text>",
    ]
    for box in boxes:
        if box.edge is not None:
            parent = where[box.edge.parent]
            x1, y1, x2, y2 = parent.x + BOX_W / 2, parent.y + BOX_H, box.x + BOX_W / 2, box.y
            parts.append(f'<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke="black"/>')
            for k, line in enumerate(_label(box.edge)):
                parts.append(
                    f'<text x="{(x1 + x2) / 2 + 6}" y="{(y1 + y2) / 2 + 14 * k}" '
                    f'font-family="sans-serif" font-size="10">{escape(line)}</text>'
                )
    for box in boxes:
        cx, cy = box.x + BOX_W / 2, box.y + BOX_H / 2
        parts.append(
            f'<ellipse cx="{cx}" cy="{cy}" rx="{BOX_W / 2}" ry="{BOX_H / 2}" '
            'fill="white" stroke="black"/>'
        )
        parts.append(
            f'<text x="{cx}" y="{cy + 5}" text-anchor="middle" font-family="sans-serif" '
            f'font-size="13">{escape(box.name)}</text>'
        )
    parts.append("</svg>")
    return "\n".join(parts) + "\n"


def raster(buffer: TfBuffer, path: Path, title: str) -> None:
    """Draw the tree to a PNG or PDF file with Pillow."""
    from PIL import Image, ImageDraw

    boxes, width, height = layout(buffer)
    where = {b.name: b for b in boxes}
    image = Image.new("RGB", (width, height), "white")
    draw = ImageDraw.Draw(image)
    draw.text((MARGIN, MARGIN - 20), title, fill="black", font_size=14)
    for box in boxes:
        if box.edge is not None:
            parent = where[box.edge.parent]
            x1, y1, x2, y2 = parent.x + BOX_W / 2, parent.y + BOX_H, box.x + BOX_W / 2, box.y
            draw.line([(x1, y1), (x2, y2)], fill="black", width=1)
            draw.polygon([(x2, y2), (x2 - 5, y2 - 10), (x2 + 5, y2 - 10)], fill="black")
            draw.multiline_text(
                ((x1 + x2) / 2 + 6, (y1 + y2) / 2 - 10),
                "\n".join(_label(box.edge)),
                fill="black",
                font_size=10,
            )
    for box in boxes:
        draw.ellipse([box.x, box.y, box.x + BOX_W, box.y + BOX_H], fill="white", outline="black")
        draw.text(
            (box.x + BOX_W / 2, box.y + BOX_H / 2),
            box.name,
            fill="black",
            font_size=13,
            anchor="mm",
        )
    image.save(path, "PDF" if path.suffix.lower() == ".pdf" else "PNG")


def write(buffer: TfBuffer, path: Path, title: str = "view_frames Result") -> None:
    """Write the tree as .svg, .png or .pdf."""
    if path.suffix.lower() == ".svg":
        path.write_text(svg(buffer, title), encoding="utf-8")
    else:
        raster(buffer, path, title)
