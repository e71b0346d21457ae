"""Output helpers shared by the CLI and the studies: markdown tables and atomic figure files."""

from __future__ import annotations

import struct

import pytest
from matplotlib.figure import Figure

from balancer.errors import OutputError
from balancer.plots import save_figure, save_png
from balancer.report import markdown_table


def test_markdown_table_aligns_first_column_left_and_the_others_right():
    text = markdown_table(["case", "rms (N)", "max (N)"], [["PB1", "1.5", "2"], ["PB2", "0", "0"]])
    assert text == (
        "| case | rms (N) | max (N) |\n"
        "|:---|---:|---:|\n"
        "| PB1 | 1.5 | 2 |\n"
        "| PB2 | 0 | 0 |"
    )


def _png_size(path) -> tuple[int, int]:
    """Width and height from the PNG's IHDR chunk (read independently of matplotlib)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_save_png_writes_one_png_at_the_asked_resolution_and_no_temporary_file(tmp_path):
    fig = Figure(figsize=(4.0, 3.0))
    fig.add_subplot().plot([0, 1], [1, 0])
    written = save_png(fig, tmp_path / "curve.svg", dpi=50)  # the suffix is made .png
    assert written == tmp_path / "curve.png"
    assert _png_size(written) == (200, 150)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["curve.png"]


def test_save_figure_writes_the_type_its_extension_names_and_nothing_on_failure(tmp_path):
    fig = Figure(figsize=(2.0, 1.0))
    fig.add_subplot().plot([0, 1], [0, 1])
    assert save_figure(fig, tmp_path / "report.png") == tmp_path / "report.png"
    assert _png_size(tmp_path / "report.png") == (300, 150)  # 150 dpi
    save_figure(fig, tmp_path / "report.svg")
    assert (tmp_path / "report.svg").read_text().lstrip().startswith("<?xml")
    save_figure(fig, tmp_path / "report.pdf")
    assert (tmp_path / "report.pdf").read_bytes()[:5] == b"%PDF-"
    with pytest.raises(OutputError, match="missing/x.png: cannot write the file"):
        save_png(fig, tmp_path / "missing" / "x.png")
    with pytest.raises(OutputError, match="use one of .png, .svg, .pdf"):
        save_figure(fig, tmp_path / "report.jpg")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.pdf", "report.png",
                                                          "report.svg"]
