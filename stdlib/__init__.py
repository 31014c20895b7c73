"""mechc's cell library: one file per cell (or cell family). See docs/write-a-cell.md."""
