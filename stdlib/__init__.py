"""mechc's cell library, one file per cell, importable as ``mechc.stdlib`` (the files stay in
the repository's top-level ``stdlib/``). See docs/write-a-cell.md."""
