"""mechc's cell library: one file per cell. See docs/write-a-cell.md."""
